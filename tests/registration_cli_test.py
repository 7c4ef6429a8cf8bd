#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
# Helpers of registration_cli_test.sh: crop a PLY skin into a moved partial "reconstruction", and
# check a tool_from_image JSON against the truth at the plan's targets.
import json
import sys

import numpy as np


def read_ply(path):
    data = open(path, 'rb').read()
    end = data.index(b'end_header\n') + len(b'end_header\n')
    header = data[:end].decode().split('\n')
    count = int(next(l for l in header if l.startswith('element vertex')).split()[2])
    props = [l.split()[2] for l in header if l.startswith('property float')]
    values = np.frombuffer(data[end:end + count * 4 * len(props)], dtype='<f4')
    values = values.reshape(count, len(props)).astype(np.float64)
    return values[:, 0:3], values[:, props.index('nx'):props.index('nx') + 3]


def truth():  # tool_from_image: 20 deg about (1, 2, 3), then (30, -40, 25) mm
    axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    angle = np.radians(20.0)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    m[:3, 3] = [30.0, -40.0, 25.0]
    return m


def crop(skin_path, out_path, region):
    points, normals = read_ply(skin_path)
    lo, hi = points.min(0), points.max(0)
    if region == 'face':  # seen from the front (LPS anterior is -y), above the lower fifth
        keep = (normals[:, 1] < -0.35) & (points[:, 2] > lo[2] + 0.2 * (hi[2] - lo[2]))
    else:  # 'vertex': a 40 mm cap on top of the head: smooth, sphere-like
        keep = points[:, 2] > hi[2] - 12.0
    m = truth()
    p = points[keep] @ m[:3, :3].T + m[:3, 3]
    n = normals[keep] @ m[:3, :3].T
    with open(out_path, 'w') as f:
        f.write('ply\nformat ascii 1.0\nelement vertex %d\n' % len(p))
        f.write(''.join('property float %s\n' % a for a in ('x', 'y', 'z', 'nx', 'ny', 'nz')))
        f.write('end_header\n')
        for a, b in zip(p, n):
            f.write('%.6f %.6f %.6f %.6f %.6f %.6f\n' % (*a, *b))


def check(transform_path, plan_path, max_tre_mm):
    m = np.array(json.load(open(transform_path))['target_from_source'])
    t = truth()
    worst = 0.0
    for markup in json.load(open(plan_path))['markups']:
        q = np.array(markup['controlPoints'][1]['position'] + [1.0])
        worst = max(worst, np.linalg.norm((m @ q - t @ q)[:3]))
    print('worst TRE at the plan targets: %.4f mm' % worst)
    sys.exit(0 if worst <= max_tre_mm else 1)


if __name__ == '__main__':
    if sys.argv[1] == 'crop':
        crop(sys.argv[2], sys.argv[3], sys.argv[4])
    else:
        check(sys.argv[2], sys.argv[3], float(sys.argv[4]))
