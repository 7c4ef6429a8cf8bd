#!/usr/bin/python3
# SPDX-License-Identifier: BSD-3-Clause
"""Independent oracle for tofnav's decode of hl2ss AHAT (port 3804) H.264/HEVC recordings.

Usage: hl2ss_h26x_oracle.py ENCODED.bin DECODED_RAW.bin

ENCODED.bin is an HL2SSV23 AHAT recording with profile_ab 0..3 (H264 base/main/high, HEVC main)
and profile_z 0 (SAME) or 1 (ZDEPTH). DECODED_RAW.bin is tofnav's decode of it, written as a
SAME+RAW recording (AB blob = u16 depth[512*512] then u16 AB[512*512]). This script decodes every AB
access unit with libavcodec (PyAV), applies the hl2ss client recovery written from the format note
(the format facts of docs/ahat.md 3 and 3.6, not tofnav's code), and checks pixel for pixel:
  SAME:   depth_mm = 4*Y; AB(r, c) = code(r, 2*(c//2))^2 with the codes taken from the U/V planes
          (U[k][j] = A(AB[r][4m]), V[k][j] = A(AB[r][4m+2]), m = j mod 128, r = 2k + j div 128).
  ZDEPTH: AB = Y^2. The Zdepth blob cannot be decoded here, so tofnav's depth is only checked to be
          0 or 201..1055 mm, with values >= 750 mm even (Zdepth quantisation).
It also checks frame count and per-frame timestamps. Packets with size_ab == 0 are skipped.
Exit status: 0 no difference, 1 a difference, 2 a format or decode error, 77 numpy/PyAV missing.
"""
import collections
import struct
import sys

try:
    import av
    import numpy as np
except ImportError as error:
    print(f"hl2ss_h26x_oracle.py: {error}", file=sys.stderr)
    sys.exit(77)

MAGIC = b"HL2SSV23"
PORT_AHAT = 3804
W = H = 512
RAW_AB_BYTES = 2 * 2 * W * H
PROFILES_AB = {0: ("H264_BASE", "h264"), 1: ("H264_MAIN", "h264"),
               2: ("H264_HIGH", "h264"), 3: ("HEVC_MAIN", "hevc"), 255: ("RAW", None)}
PROFILES_Z = {0: "SAME", 1: "ZDEPTH"}


class FormatError(Exception):
    pass


class Recording:
    """Streams the packets of one HL2SSV23 file (header in __init__, packets from packets())."""

    def __init__(self, path):
        self.path = path
        self.file = open(path, "rb")
        self.offset = 0
        if self._read(8, "magic") != MAGIC:
            raise FormatError(f"{path}: byte 0: magic is not {MAGIC.decode()}")
        port, user_len = struct.unpack("<HI", self._read(6, "port/user_len"))
        if port != PORT_AHAT:
            raise FormatError(f"{path}: byte 8: port {port}, expected {PORT_AHAT} (AHAT)")
        self._read(user_len, "user data")
        self.config_offset = self.offset
        (self.mode, self.divisor, self.profile_z, self.profile_ab, self.level, self.bitrate,
         n_options) = struct.unpack("<5BIB", self._read(10, "configuration"))
        self._read(16 * n_options, "encoder options")
        if self.profile_z not in PROFILES_Z or self.profile_ab not in PROFILES_AB:
            raise FormatError(f"{path}: byte {self.config_offset + 2}: unsupported "
                              f"profile_z {self.profile_z} / profile_ab {self.profile_ab}")
        self.name = f"{PROFILES_Z[self.profile_z]}+{PROFILES_AB[self.profile_ab][0]}"

    def _read(self, n, what, eof_ok=False):
        data = self.file.read(n)
        if len(data) != n and not (eof_ok and not data):
            raise FormatError(f"{self.path}: byte {self.offset}: truncated {what} "
                              f"({len(data)} of {n} bytes)")
        self.offset += len(data)
        return data

    def packets(self):
        """Yields (byte offset, timestamp, zdepth blob, AB blob); skips size_ab == 0 packets."""
        while True:
            start = self.offset
            head = self._read(12, "packet header", eof_ok=True)
            if not head:
                return
            timestamp, payload_size = struct.unpack("<QI", head)
            if payload_size < 8:
                raise FormatError(f"{self.path}: byte {start + 8}: payload_size {payload_size} < 8")
            size_z, size_ab = struct.unpack("<II", self._read(8, "size_z/size_ab"))
            trailer = payload_size - 8 - size_z - size_ab
            if trailer not in (0, 8):  # 8: sensor_ticks; 0: files from before 2024-08-12
                raise FormatError(f"{self.path}: byte {start + 8}: payload_size {payload_size} "
                                  f"!= 8 + size_z {size_z} + size_ab {size_ab} + 8")
            zdepth = self._read(size_z, "Zdepth blob")
            ab = self._read(size_ab, "AB blob")
            self._read(trailer, "sensor_ticks")
            if self.mode == 1:
                self._read(64, "pose")
            if size_ab:
                yield start, timestamp, zdepth, ab


def planes(frame):
    """Raw 8-bit Y, U, V codes of a decoded yuv420p frame (line padding dropped)."""
    if frame.format.name not in ("yuv420p", "yuvj420p") or (frame.width, frame.height) != (W, H):
        raise FormatError(f"decoded frame is {frame.format.name} {frame.width}x{frame.height}, "
                          f"expected yuv420p {W}x{H}")
    out = []
    for plane, (w, h) in zip(frame.planes, ((W, H), (W // 2, H // 2), (W // 2, H // 2))):
        rows = np.frombuffer(plane, np.uint8)[: plane.line_size * h].reshape(h, plane.line_size)
        out.append(rows[:, :w])
    return out


def recover(frame, profile_z):
    """hl2ss client recovery: returns (depth mm or None for ZDEPTH, AB), both uint16 512x512."""
    y, u, v = planes(frame)
    if profile_z == 1:  # ZDEPTH: Y[r][c] = A(AB[r][c]), UV unused
        return None, y.astype(np.uint16) ** 2
    depth = y.astype(np.uint16) * 4
    # U[k][j] holds the code of AB row r = 2k + j div 128, column 4m (m = j mod 128); V column
    # 4m + 2. Row-major, U viewed as 512 x 128 is exactly [r][m]; interleave U/V to get the codes
    # of the even columns 0, 2, 4, ... of each row, square, and repeat them into the odd columns.
    codes = np.empty((H, W // 2), np.uint16)
    codes[:, 0::2] = u.reshape(H, W // 4)
    codes[:, 1::2] = v.reshape(H, W // 4)
    return depth, np.repeat(codes ** 2, 2, axis=1)


def zdepth_off_grid(depth):
    """Count of depth pixels that Zdepth (+ D' invalidation) cannot produce."""
    ok = (depth == 0) | ((depth >= 201) & (depth <= 749)) | \
        ((depth >= 750) & (depth <= 1055) & (depth % 2 == 0))
    return int(np.count_nonzero(~ok))


def main(argv):
    if len(argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    enc = Recording(argv[1])
    raw = Recording(argv[2])
    if enc.profile_ab == 255:
        raise FormatError(f"{enc.path}: byte {enc.config_offset + 3}: profile_ab 255 (RAW), "
                          "expected H.264/HEVC")
    if (raw.profile_z, raw.profile_ab) != (0, 255):
        raise FormatError(f"{raw.path}: byte {raw.config_offset + 2}: decoded file is {raw.name}, "
                          "expected SAME+RAW")
    codec = av.CodecContext.create(PROFILES_AB[enc.profile_ab][1], "r")
    raw_packets = raw.packets()
    pending = collections.deque()  # (offset, timestamp) of sent packets whose frame is not out yet
    stats = dict(frames=0, depth=0, ab=0, worst_depth=(0, -1), worst_ab=(0, -1), mismatch=[])
    first_ts = last_ts = None
    ab_bytes = 0

    def compare(frame):
        offset, ts = pending.popleft()
        index = stats["frames"]
        try:
            raw_offset, raw_ts, _, blob = next(raw_packets)
        except StopIteration:
            stats["mismatch"].append(f"{raw.path} ends before frame {index} "
                                     f"({enc.path} byte {offset})")
            return
        stats["frames"] += 1
        if len(blob) != RAW_AB_BYTES:
            raise FormatError(f"{raw.path}: byte {raw_offset}: size_ab {len(blob)}, "
                              f"expected {RAW_AB_BYTES}")
        if raw_ts != ts:
            stats["mismatch"].append(f"frame {index}: timestamp {raw_ts} in {raw.path} "
                                     f"(byte {raw_offset}), {ts} in {enc.path} (byte {offset})")
        got = np.frombuffer(blob, "<u2").reshape(2, H, W)
        depth, ab = recover(frame, enc.profile_z)
        if depth is None:
            n_depth = zdepth_off_grid(got[0])
        else:
            n_depth = int(np.count_nonzero(got[0] != depth))
        n_ab = int(np.count_nonzero(got[1] != ab))
        stats["depth"] += n_depth
        stats["ab"] += n_ab
        stats["worst_depth"] = max(stats["worst_depth"], (n_depth, index))
        stats["worst_ab"] = max(stats["worst_ab"], (n_ab, index))

    for offset, ts, _, blob in enc.packets():
        first_ts = ts if first_ts is None else first_ts
        last_ts = ts
        ab_bytes += len(blob)
        pending.append((offset, ts))
        try:
            frames = codec.decode(av.Packet(blob))
        except av.AVError as error:
            raise FormatError(f"{enc.path}: byte {offset}: decoding failed: {error}")
        for frame in frames:
            compare(frame)
    if pending:  # a frame is missing: flush the decoder
        for frame in codec.decode(None):
            if pending:
                compare(frame)
    if pending:
        raise FormatError(f"{enc.path}: byte {pending[0][0]}: {len(pending)} packet(s) "
                          "gave no decoded frame")
    if first_ts is None:
        raise FormatError(f"{enc.path}: byte {enc.offset}: no packet with an AB blob")
    extra = sum(1 for _ in raw_packets)
    if extra:
        stats["mismatch"].append(f"{raw.path} has {extra} more frame(s) than {enc.path}")

    span_s = (last_ts - first_ts) / 1e7 if first_ts is not None else 0.0
    rate = f"{ab_bytes * 8 / span_s / 1e6:.3f} Mbit/s" if span_s > 0 else "n/a"
    print(f"profile {enc.name} (level {enc.level}, configured bitrate {enc.bitrate} bit/s): "
          f"measured AB stream bitrate {rate} ({ab_bytes} B over {span_s:.3f} s)")
    depth_what = ("depth pixels off the Zdepth grid (Zdepth not decoded: only 0 or 201..1055 mm, "
                  ">= 750 even, checked)" if enc.profile_z == 1 else "differing depth pixels")

    def worst(key):
        count, index = stats[key]
        return f"worst frame {index}: {count}" if count else "worst frame -"

    print(f"{enc.name}: {stats['frames']} frames compared, {depth_what} {stats['depth']} "
          f"({worst('worst_depth')}), differing AB pixels {stats['ab']} ({worst('worst_ab')})")
    for line in stats["mismatch"]:
        print(f"MISMATCH: {line}")
    return 1 if stats["depth"] or stats["ab"] or stats["mismatch"] else 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except FormatError as error:
        print(f"hl2ss_h26x_oracle.py: format error: {error}", file=sys.stderr)
        sys.exit(2)
    except OSError as error:
        print(f"hl2ss_h26x_oracle.py: {error}", file=sys.stderr)
        sys.exit(2)
