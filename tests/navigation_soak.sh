#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Soak test of `tofnav navigate` (issue 8): a recording replayed in a loop at its recorded pace
# (45 Hz) for DURATION seconds while an OpenIGTLink client connects and disconnects again and
# again (some connections send 3D Slicer's v2 STATUS, some a corrupted CRC, some stall without
# reading). Fails on a crash, a non-zero exit, or resident memory growing by more than
# MAX_GROWTH_KB between the first minute and the end.
#   tests/navigation_soak.sh TOFNAV CASE_DIR [DURATION_S=600]
# CASE_DIR: `tofnav simulate evd-usecase --out CASE_DIR --frames 300` then
# `tests/navigation_case_from_truth.py CASE_DIR`.
set -euo pipefail
tofnav=$1
case_dir=$2
duration=${3:-600}
max_growth_kb=${MAX_GROWTH_KB:-8192}
python=/usr/bin/python3
log=$(mktemp -d)
port=$($python -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')

"$tofnav" navigate "$case_dir/rm_depth_ahat.bin" --calibration "$case_dir/calibration" \
  --tool "$case_dir/tools/reference.json" --registration "$case_dir/tool_from_image.json" \
  --plan "$case_dir/plan.mrk.json" --skin "$case_dir/skin_truth.ply" --igtl-port "$port" \
  --realtime --loop --duration-s "$duration" -q --json >"$log/summary.json" 2>"$log/stderr.txt" &
pid=$!

# The churning client: runs until the server goes away.
$python - "$port" >"$log/client.txt" 2>&1 <<'EOF' &
import random, socket, struct, sys, time
port = int(sys.argv[1])
def crc64(data):
    crc = 0
    for b in data:
        crc ^= b << 56
        for _ in range(8):
            crc = ((crc << 1) ^ 0x42F0E1EBA9EA3693) & 0xFFFFFFFFFFFFFFFF if crc >> 63 else (crc << 1) & 0xFFFFFFFFFFFFFFFF
    return crc
def message(version, kind, name, body, corrupt=False):
    header = struct.pack(">H12s20sQQQ", version, kind.encode(), name.encode(), 0, len(body), crc64(body))
    if corrupt:
        body = bytes([body[0] ^ 0xFF]) + body[1:]
    return header + body
v2_status = message(2, "STATUS", "", struct.pack(">HHII", 12, 2, 0, 0) + bytes(30) + struct.pack(">H", 0))
bad = message(1, "STRING", "Bad", struct.pack(">HH", 3, 5) + b"hello", corrupt=True)
rng = random.Random(1)
connections = received = 0
start = time.time()
while True:
    try:
        s = socket.create_connection(("127.0.0.1", port), timeout=2)
    except OSError:
        if time.time() - start > 20:
            break  # the server has gone
        time.sleep(0.2)
        continue
    connections += 1
    kind = rng.randrange(4)
    try:
        if kind == 0:
            s.sendall(v2_status)
        elif kind == 1:
            s.sendall(bad)
        if kind == 2:
            time.sleep(rng.uniform(1.0, 3.0))  # stalled: never reads
        else:
            until = time.time() + rng.uniform(0.2, 2.0)
            while time.time() < until:
                data = s.recv(65536)
                if not data:
                    break
                received += len(data)
    except OSError:
        pass
    s.close()
    start = time.time()
print(f"connections {connections}, bytes received {received}")
EOF
client=$!

# Resident memory every 10 s.
samples=()
while kill -0 "$pid" 2>/dev/null; do
  rss=$(awk '/^VmRSS/ {print $2}' "/proc/$pid/status" 2>/dev/null || true)
  [ -n "$rss" ] && samples+=("$rss") && echo "$(date +%s) rss_kb=$rss" >>"$log/rss.txt"
  sleep 10
done
status=0
wait "$pid" || status=$?
wait "$client" || true
cat "$log/summary.json" "$log/client.txt"
if [ "$status" -ne 0 ]; then
  echo "soak: tofnav navigate exited with $status" >&2
  cat "$log/stderr.txt" >&2
  exit 1
fi
n=${#samples[@]}
if [ "$n" -lt 8 ]; then
  echo "soak: too few memory samples ($n)" >&2
  exit 1
fi
first=${samples[6]}  # after one minute: buffers and the page cache of the first pass are in
last=${samples[$((n - 1))]}
echo "soak: RSS after 60 s ${first} kB, at the end ${last} kB (${n} samples, log in $log)"
if [ $((last - first)) -gt "$max_growth_kb" ]; then
  echo "soak: memory grew by $((last - first)) kB" >&2
  exit 1
fi
echo "soak: ok"
