#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Where a suite run's depth correction goes wrong, measured against the simulator's truth
(docs/correction.md 2.11). Each RUN is a suite case folder (DIR/CASE; its seed* folder holds
session/, depth_model.json and frf.json), as `tofnav evaluate suite --out DIR` leaves it.

  removal RUN TWIN      the multipath the removal faced and what it left, by incidence, against TWIN:
                        the same case and seed rendered with "multipath_gain": 0 (a suite file)
  delay RUN TWIN        the removal repeated on the head's pixels without and with the skin's
                        delay, and from the true ranges, by the multipath put in (docs/correction.md
                        7.3)
  share RUN TWIN        the shift the removal takes out against the one the multipath put in, by
                        incidence (trimmed means: a ZDEPTH range is whole millimetres)
  oracle RUN            C1, C3, C4 of the pipeline's own correction fitted to the true ranges over
                        the head, beside the identified ones; prints the model-file edit too
  stickers RUN C1,C3,C4 Eq. (6) per forehead sticker under that model, measured and on true ranges,
                        and what the sticker's own points read (f_rf and its entrance term) - true
  near RUN C1,C3,C4     the head's range error under that model by chessboard distance [px] to the
                        nearest marker pixel (docs/correction.md 2.12)
  region RUN C1,C3,C4   the head's normal error under that model by distance from the forehead
                        stickers' centroid (0-30, 30-60, ... mm)

Needs the Python bindings: PYTHONPATH=build/<dir>/python. Reads, never writes.
"""
import glob
import json
import sys

import numpy as np
from scipy.spatial import cKDTree

import tofnav


def case_dir(run):
    found = sorted(glob.glob(run + "/seed*"))
    if not found and glob.glob(run + "/session"):
        return run  # a suite run with one seed and no stability runs
    if not found:
        sys.exit(f"{run}: no seed* folder (a suite case folder was expected)")
    return found[0]


class Run:
    def __init__(self, run, with_skin=True):
        self.dir = case_dir(run)
        s = self.dir + "/session"
        self.recording = tofnav.open_recording(s + "/rm_depth_ahat.bin")
        self.camera = tofnav.AhatCamera(tofnav.read_hl2ss_calibration(s + "/calibration/rm_depth_ahat"))
        self.truth = json.load(open(s + "/truth.json"))
        self.true_range = np.memmap(s + "/truth_range_f32.bin", dtype="<f4", mode="r").reshape(-1, 512, 512)
        if with_skin:  # a twin lends its recording only
            self.tree = cKDTree(np.asarray(tofnav.read_mesh(s + "/skin_truth.ply").vertices))
        self.forehead_from_image = np.array(self.truth["forehead_markers_from_image"])

    def model(self, coefficients=None, multipath=True):
        m, frf = tofnav.read_depth_model(self.dir + "/depth_model.json")
        if coefficients is not None:
            m.c1_mm, m.c3_mm, m.c4_mm = coefficients
        if not multipath:
            options = m.multipath
            options.enabled = False
            m.multipath = options
        return m, frf

    def correct(self, frame, model, frf):
        options = tofnav.CorrectRangeOptions()
        options.marker_model = frf
        return tofnav.correct_frame(frame, self.camera, model, options)

    def head_mask(self, i, valid):
        """Pixels whose true point lies within 1.5 mm of the true skin."""
        t = np.ascontiguousarray(self.true_range[i])
        points = np.asarray(self.camera.points_from_range(t))
        ahat_from_forehead = np.array(self.truth["frames"][i]["ahat_from_forehead_markers"])
        image_from_ahat = np.linalg.inv(ahat_from_forehead @ self.forehead_from_image)
        ok = valid & (t > 0)
        q = points[ok] @ image_from_ahat[:3, :3].T + image_from_ahat[:3, 3]
        distance, _ = self.tree.query(q, distance_upper_bound=3.0)
        head = np.zeros_like(ok)
        head[ok] = distance < 1.5
        return head

    def frames(self, count):
        return np.linspace(0, len(self.recording) - 1, count).astype(int)


def removal(run_path, twin_path):
    run, twin = Run(run_path), Run(twin_path, with_skin=False)
    zero = (0.0, 0.0, 0.0)
    with_removal, frf = run.model(zero)
    without, _ = run.model(zero, multipath=False)
    from scipy import ndimage
    left, incidence, to_marker = [], [], []
    for i in run.frames(20):
        a = run.correct(run.recording.read_frame(int(i)), with_removal, frf)
        removed = np.asarray(a["range_mm"], float)
        clean = np.asarray(twin.correct(twin.recording.read_frame(int(i)), without, frf)["range_mm"], float)
        theta = np.asarray(a["incidence_rad"], float)
        head = run.head_mask(i, (removed > 0) & (clean > 0) & np.isfinite(theta))
        marker = np.zeros(removed.shape, bool)
        for m in a["markers"]:
            px = np.asarray(m["pixels"])
            marker[px[:, 1], px[:, 0]] = True
        left.append((removed - clean)[head])
        incidence.append(np.degrees(theta[head]))
        to_marker.append(ndimage.distance_transform_cdt(~marker, metric="chessboard")[head])
    left, incidence, to_marker = map(np.concatenate, (left, incidence, to_marker))
    print(f"left by the removal (+ = range long), median {np.median(left):+.2f} mm,"
          f" trimmed mean {trimmed_mean(left):+.3f} mm")
    for lo in range(0, 75, 15):
        k = (incidence >= lo) & (incidence < lo + 15)
        if k.any():
            print(f"  {lo:2d}-{lo + 15:2d} deg: {np.median(left[k]):+.2f} mm ({k.sum()} px)")
    for lo, hi in [(0, 10), (10, 20), (20, 30), (30, 10**6)]:
        k = (to_marker >= lo) & (to_marker < hi)
        if k.any():  # trimmed means: whole-millimetre ranges make medians step
            far = f"{lo}+" if hi > 1000 else f"{lo}-{hi}"
            print(f"  {far} px from a marker: {trimmed_mean(left[k]):+.3f} mm ({k.sum()} px)")


def trimmed_mean(x):
    """Mean of the 5th-95th percentile: medians of whole-millimetre differences step by 1 mm."""
    lo, hi = np.percentile(x, [5, 95])
    return x[(x >= lo) & (x <= hi)].mean()


def share(run_path, twin_path):
    run, twin = Run(run_path), Run(twin_path, with_skin=False)
    zero = (0.0, 0.0, 0.0)
    with_removal, frf = run.model(zero)
    without, _ = run.model(zero, multipath=False)
    made, taken, incidence = [], [], []
    for i in run.frames(12):
        frame = run.recording.read_frame(int(i))
        a = run.correct(frame, with_removal, frf)
        removed = np.asarray(a["range_mm"], float)
        raw = np.asarray(run.correct(frame, without, frf)["range_mm"], float)
        clean = np.asarray(twin.correct(twin.recording.read_frame(int(i)), without, frf)["range_mm"], float)
        theta = np.asarray(a["incidence_rad"], float)
        head = run.head_mask(i, (removed > 0) & (clean > 0) & (raw > 0) & np.isfinite(theta))
        made.append((raw - clean)[head])
        taken.append((raw - removed)[head])
        incidence.append(np.degrees(theta[head]))
    made, taken, incidence = map(np.concatenate, (made, taken, incidence))
    print(f"multipath {trimmed_mean(made):.2f} mm, removed {trimmed_mean(taken):.2f} mm"
          f" ({trimmed_mean(taken) / trimmed_mean(made):.2f} of it)")
    for lo in range(0, 75, 15):
        k = (incidence >= lo) & (incidence < lo + 15)
        if k.any():
            m, t = trimmed_mean(made[k]), trimmed_mean(taken[k])
            print(f"  {lo:2d}-{lo + 15:2d} deg: {m:.2f} -> removed {t:.2f} ({t / m:.2f})")


def oracle(run_path):
    run = Run(run_path)
    basis = {c: run.model(c) for c in [(0, 0, 0), (0, 1, 0), (0, 0, 1)]}
    r0, b3, b4, cos = [], [], [], []
    for i in run.frames(30):
        frame = run.recording.read_frame(int(i))
        out = {c: run.correct(frame, *mf) for c, mf in basis.items()}
        c0, c3, c4 = (np.asarray(out[c]["range_mm"], float) for c in [(0, 0, 0), (0, 1, 0), (0, 0, 1)])
        theta = np.asarray(out[(0, 0, 0)]["incidence_rad"], float)
        head = run.head_mask(i, (c0 > 0) & (c3 > 0) & (c4 > 0) & np.isfinite(theta))
        t = run.true_range[i][head]
        r0.append(c0[head] - t)
        b3.append((c0 - c3)[head])
        b4.append((c0 - c4)[head])
        cos.append(np.cos(theta[head]))
    r0, b3, b4, cos = map(np.concatenate, (r0, b3, b4, cos))
    x = np.stack([np.ones_like(r0), b3, b4], 1)
    weight = cos**2  # the residual as a distance along the normal
    for _ in range(6):  # Huber 1 mm by reweighting
        root = np.sqrt(weight)
        coefficients = np.linalg.lstsq(x * root[:, None], r0 * root, rcond=None)[0]
        normal = (r0 - x @ coefficients) * cos
        weight = cos**2 * np.where(np.abs(normal) < 1.0, 1.0, 1.0 / np.abs(normal))
    identified, _ = run.model()
    fitted = np.array([identified.c1_mm, identified.c3_mm, identified.c4_mm])
    identified_normal = (r0 - x @ fitted) * cos
    print("oracle     C1 %.3f C3 %+.3f C4 %.3f: normal residual median %+.3f mm" % (*coefficients, np.median(normal)))
    print("identified C1 %.3f C3 %+.3f C4 %.3f: normal residual median %+.3f mm" % (*fitted, np.median(identified_normal)))
    print("model file edit: c1_mm %.4f c3_mm %.4f c4_mm %.4f" % tuple(coefficients))


def eq6_distance(marker_points, neighbours):
    """Median signed distance (+ towards the camera) of marker points to the cubic through the neighbours."""
    centre = neighbours.mean(0)
    axes = np.linalg.svd(neighbours - centre, full_matrices=False)[2]

    def terms(x, y):
        return np.stack([np.ones_like(x), x, y, x * x, x * y, y * y, x**3, x * x * y, x * y * y, y**3], 1)

    local = (neighbours - centre) @ axes.T
    cubic = np.linalg.lstsq(terms(local[:, 0], local[:, 1]), local[:, 2], rcond=None)[0]
    m = (marker_points - centre) @ axes.T
    d = m[:, 2] - terms(m[:, 0], m[:, 1]) @ cubic
    return np.median(-d if np.dot(axes[2], -centre) < 0 else d), axes[2]


def stickers(run_path, coefficients):
    run = Run(run_path)
    model, frf = run.model(coefficients)
    gain = frf.entrance_gain_mm_per_rad
    centres = np.array([m["centre_in_tool"] for m in run.truth["tools"]["forehead_markers"]["markers"]])
    rows = {k: [] for k in range(len(centres))}
    for i in run.frames(40):
        out = run.correct(run.recording.read_frame(int(i)), model, frf)
        r = np.asarray(out["range_mm"], np.float32)
        t = np.ascontiguousarray(run.true_range[i])
        p, pt = np.asarray(run.camera.points_from_range(r)), np.asarray(run.camera.points_from_range(t))
        pose = np.array(run.truth["frames"][i]["ahat_from_forehead_markers"])
        where = centres @ pose[:3, :3].T + pose[:3, 3]
        for marker in out["markers"]:
            gap = np.linalg.norm(where - np.asarray(marker["centroid_in_ahat"]), axis=1)
            k = int(gap.argmin())
            px = np.asarray(marker["pixels"])
            px = px[(r[px[:, 1], px[:, 0]] > 0) & (t[px[:, 1], px[:, 0]] > 0)]
            ring = np.linalg.norm(pt - where[k], axis=2)
            nb = (out["labels"] == tofnav.PIXEL_HEAD) & (r > 0) & (t > 0) & (ring < 30) & (ring > 8)
            if gap[k] > 6 or len(px) < 5 or nb.sum() < 30:
                continue
            # f_rf's entrance-angle term on tape, as the identification applies it
            points = p[px[:, 1], px[:, 0]]
            ranges = np.linalg.norm(points, axis=1)
            rays = points / ranges[:, None]
            _, normal = eq6_distance(points, p[nb])
            shortened = rays * (ranges - gain * np.arccos(np.clip(np.abs(rays @ normal), 0, 1)))[:, None]
            measured, _ = eq6_distance(shortened, p[nb])
            # on true ranges; its normal gives the sticker's own read its entrance term
            true, true_normal = eq6_distance(pt[px[:, 1], px[:, 0]], pt[nb])
            true_rays = pt[px[:, 1], px[:, 0]] / t[px[:, 1], px[:, 0]][:, None]
            entrance = np.arccos(np.clip(np.abs(true_rays @ true_normal), 0, 1))
            read = r[px[:, 1], px[:, 0]] - gain * entrance - t[px[:, 1], px[:, 0]]
            rows[k].append((measured, true, np.median((r - t)[nb]), np.median(read), np.mean(read),
                            np.degrees(np.median(entrance))))
    for k, values in rows.items():
        if values:
            v = np.median(np.array(values), 0)
            print(f"sticker {k}: {len(values)} frames, Eq. (6) measured {v[0]:+.2f} mm, on true ranges {v[1]:+.2f} mm;"
                  f" neighbours corrected - true {v[2]:+.2f} mm; the sticker reads {v[3]:+.2f} mm"
                  f" (mean {v[4]:+.2f}) at {v[5]:.0f} deg of entrance")


def near(run_path, coefficients):
    from scipy import ndimage
    run = Run(run_path)
    model, frf = run.model(coefficients)
    errors = {k: [] for k in range(21)}  # 20: 20 px and beyond
    for i in run.frames(20):
        out = run.correct(run.recording.read_frame(int(i)), model, frf)
        r = np.asarray(out["range_mm"], float)
        t = np.ascontiguousarray(run.true_range[i]).astype(float)
        marker = np.zeros(r.shape, bool)
        for m in out["markers"]:
            px = np.asarray(m["pixels"])
            marker[px[:, 1], px[:, 0]] = True
        distance = ndimage.distance_transform_cdt(~marker, metric="chessboard")
        head = run.head_mask(i, (r > 0) & (t > 0)) & (out["labels"] == tofnav.PIXEL_HEAD)
        for k in errors:
            chosen = head & (distance == k if k < 20 else distance >= 20)
            if chosen.any():
                errors[k].append((r - t)[chosen])
    for k, values in errors.items():
        if values:
            v = np.concatenate(values)
            print(f"{k:2d}{'+' if k == 20 else ' '} px: corrected - true {np.median(v):+.3f} mm ({len(v)} px)")


def region(run_path, coefficients):
    run = Run(run_path)
    model, frf = run.model(coefficients)
    centres = np.array([m["centre_in_tool"] for m in run.truth["tools"]["forehead_markers"]["markers"]])
    image_from_forehead = np.linalg.inv(run.forehead_from_image)
    centroid = (centres @ image_from_forehead[:3, :3].T + image_from_forehead[:3, 3]).mean(0)
    errors, distances = [], []
    for i in run.frames(20):
        out = run.correct(run.recording.read_frame(int(i)), model, frf)
        r = np.asarray(out["range_mm"], float)
        theta = np.asarray(out["incidence_rad"], float)
        t = np.ascontiguousarray(run.true_range[i])
        head = run.head_mask(i, (r > 0) & np.isfinite(theta)) & (out["labels"] == tofnav.PIXEL_HEAD)
        pose = np.array(run.truth["frames"][i]["ahat_from_forehead_markers"])
        image_from_ahat = np.linalg.inv(pose @ run.forehead_from_image)
        q = np.asarray(run.camera.points_from_range(t))[head] @ image_from_ahat[:3, :3].T + image_from_ahat[:3, 3]
        errors.append(((r - t) * np.cos(theta))[head])
        distances.append(np.linalg.norm(q - centroid, axis=1))
    errors, distances = np.concatenate(errors), np.concatenate(distances)
    print(f"head, normal error under the model: median {np.median(errors):+.2f} mm")
    for lo in range(0, 150, 30):
        k = (distances >= lo) & (distances < lo + 30)
        if k.sum() > 100:
            print(f"  {lo:3d}-{lo + 30:3d} mm from the stickers: {np.median(errors[k]):+.2f} mm ({100 * k.mean():.0f} %)")


def delay(run_path, twin_path):
    run, twin = Run(run_path), Run(twin_path, with_skin=False)
    without, frf = run.model((0.0, 0.0, 0.0), multipath=False)
    options = run.model()[0].multipath
    skin_mm = options.skin_delay_mm or 7.58
    rows, put_in = {}, []
    for i in run.frames(6):
        frame = run.recording.read_frame(int(i))
        c = run.correct(frame, without, frf)
        labels = np.asarray(c["labels"])
        depth = np.asarray(frame.depth).astype(np.float32)
        surface = (labels != tofnav.PIXEL_MARKER) & (labels != tofnav.PIXEL_TRANSITION) & (depth > 0)
        measured = np.where(surface, depth, 0).astype(np.float32)
        clean = np.asarray(twin.correct(twin.recording.read_frame(int(i)), without, frf)["range_mm"], float)
        skin = labels == tofnav.PIXEL_HEAD
        head = run.head_mask(i, (measured > 0) & (clean > 0))
        true = np.asarray(run.true_range[i], np.float32)
        on_true = np.where(surface & (true > 0), true + skin_mm * skin, measured).astype(np.float32)
        for name, ranges, tau in [("measured, no delay", measured, None),
                                  (f"measured, skin {skin_mm:.2f} mm", measured, skin_mm * skin),
                                  (f"true, skin {skin_mm:.2f} mm", on_true, skin_mm * skin)]:
            out, _ = tofnav.remove_multipath(ranges, np.asarray(frame.ab), run.camera, options, None,
                                             bool(frame.ab_lossy),
                                             None if tau is None else np.ascontiguousarray(tau, np.float32))
            shift = np.where(np.asarray(out) > 0, ranges - np.asarray(out, float), np.nan)
            rows.setdefault(name, []).append((measured - shift - clean)[head])
        put_in.append((measured - clean)[head])
    put_in = np.concatenate(put_in)
    print(f"multipath put in on the head: trimmed mean {trimmed_mean(put_in):+.3f} mm")
    for name, parts in rows.items():
        left = np.concatenate(parts)
        ok = np.isfinite(left)
        line = f"  {name:24s} left {trimmed_mean(left[ok]):+.3f} mm;"
        for lo, hi in [(0, 1), (1, 2), (2, 4), (4, 1000)]:
            k = ok & (put_in >= lo) & (put_in < hi)
            if k.sum() > 50:
                line += f" {lo}-{hi if hi < 1000 else ''} mm put in: {trimmed_mean(left[k]):+.2f}"
        print(line)


def main(argv):
    if len(argv) >= 3 and argv[0] == "removal":
        removal(argv[1], argv[2])
    elif len(argv) >= 3 and argv[0] == "delay":
        delay(argv[1], argv[2])
    elif len(argv) >= 3 and argv[0] == "share":
        share(argv[1], argv[2])
    elif len(argv) >= 2 and argv[0] == "oracle":
        oracle(argv[1])
    elif len(argv) >= 3 and argv[0] in ("stickers", "near", "region"):
        {"stickers": stickers, "near": near, "region": region}[argv[0]](argv[1], [float(x) for x in argv[2].split(",")])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
