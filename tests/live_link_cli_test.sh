#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# tofnav navigate hl2ss:// against tofnav serve with each fault (issue 19): the messages word for
# word, one NO_STREAM CSV row per outage, the link counts of --json, the give-up exit status and
# the refusal of another device. Short stall timeout (0.2 s) and faults after 20 packets. The
# stream is SAME+RAW (--profile raw): an H.265 encoder takes longer than 0.2 s to start (the H.265
# live path is tested in hl2ss_live_test.cpp).
# Usage: live_link_cli_test.sh TOFNAV TESTS_DIR
set -euo pipefail
tofnav=$1
tests=$2
python=/usr/bin/python3
scratch=$(mktemp -d)
servers=()
cleanup() {
  for pid in "${servers[@]}"; do kill "$pid" 2>/dev/null || true; done
  rm -rf "$scratch"
}
trap cleanup EXIT
case_dir=$scratch/case
"$tofnav" simulate evd-usecase --frames 45 --out "$case_dir" -q >/dev/null
$python "$tests/navigation_case_from_truth.py" "$case_dir" >/dev/null
free_port() { $python -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
serve() {  # serve PORT CALIBRATION FAULTS
  "$tofnav" serve "$case_dir/rm_depth_ahat.bin" --calibration "$2" --port "$1" --faults "$3" \
    2>>"$scratch/serve.txt" >/dev/null &
  servers+=($!)
  sleep 0.5
}
navigate() {  # navigate PORT NAME ARGS...: stderr in NAME.txt, summary in NAME.json, CSV in NAME.csv
  local port=$1 name=$2
  shift 2
  local status=0
  "$tofnav" navigate "hl2ss://127.0.0.1:$port" --tool "$case_dir/tools/reference.json" \
    --registration "$case_dir/tool_from_image.json" --plan "$case_dir/plan.mrk.json" --no-igtl \
    --stall-timeout-s 0.2 --profile raw --out "$scratch/$name.csv" --json "$@" \
    >"$scratch/$name.json" 2>"$scratch/$name.txt" || status=$?
  echo "$status"
}
fail() {
  echo "live_link_cli_test: $1" >&2
  for f in "$scratch"/*.txt; do echo "--- $f" >&2; cat "$f" >&2; done
  exit 1
}
expect_lines() {  # expect_lines NAME REGEX...: stderr matches these lines, in order, exactly
  local name=$1
  shift
  $python - "$scratch/$name.txt" "$@" <<'PY' || fail "$name: messages differ"
import re, sys
lines = open(sys.argv[1]).read().splitlines()
want = sys.argv[2:]
ok = len(lines) == len(want) and all(re.fullmatch(w, l) for w, l in zip(want, lines))
if not ok:
    print("got:", *lines, "want:", *want, sep="\n  ", file=sys.stderr)
sys.exit(0 if ok else 1)
PY
}

back='tofnav navigate: hl2ss://127\.0\.0\.1:[0-9]+: the stream is back after [0-9.]+ s without frames; navigating again'
refused='reconnecting failed \(the headset refuses connections: is the hl2ss app running\?\); trying again every 2\.0 s at most'
# The five faults run side by side, each on its own port.
declare -A ports
navs=()
for kind in drop reset truncate stall:1s restart:1s; do
  name=${kind%%:*}
  ports[$name]=$(free_port)
  serve "${ports[$name]}" "$case_dir/calibration" "$kind:after=20"
  (navigate "${ports[$name]}" "$name" --duration-s 3 >"$scratch/$name.status") &
  navs+=($!)
done
wait "${navs[@]}"
for name in drop reset truncate stall restart; do
  status=$(cat "$scratch/$name.status")
  [ "$status" -eq 0 ] || fail "$name: navigate exited with $status"
  peer="tofnav navigate: hl2ss://127\.0\.0\.1:${ports[$name]}: "
  case $name in
    drop) expect_lines drop "${peer}the headset closed the stream after 20 frames; reconnecting" "$back" \
      'tofnav navigate: stopped after --duration-s' ;;
    reset) expect_lines reset "${peer}the headset reset the connection after [0-9]+ frames; reconnecting" \
      "$back" 'tofnav navigate: stopped after --duration-s' ;;
    truncate) expect_lines truncate "${peer}the stream broke off inside a packet after 20 frames; reconnecting" \
      "$back" 'tofnav navigate: stopped after --duration-s' ;;
    stall) expect_lines stall "${peer}no frame from the headset for 0\.2 s after 20 frames; reconnecting" \
      "$back" 'tofnav navigate: stopped after --duration-s' ;;
    restart) expect_lines restart "${peer}the headset closed the stream after 20 frames; reconnecting" \
      "${peer}$refused" "$back" 'tofnav navigate: stopped after --duration-s' ;;
  esac
  # One NO_STREAM row per outage, between frames, and the counts of the summary.
  $python - "$scratch/$name.csv" "$scratch/$name.json" "$name" <<'PY' || fail "$name: CSV or summary"
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
link = json.load(open(sys.argv[2]))["link"]
kind = sys.argv[3]
down = [i for i, r in enumerate(rows) if r["status"] == "NO_STREAM"]
assert len(down) == 1 and 0 < down[0] < len(rows) - 1, down
i = down[0]
t = [float(rows[k]["timestamp_s"]) for k in (i - 1, i, i + 1)]
assert t[0] < t[1] < t[2] and rows[i]["world_from_image_tx_mm"] == "", (t, rows[i])
assert link["reconnects"] == 1 and link[("stalls" if kind == "stall" else "disconnects")] == 1, link
assert link["seconds_without_stream"] > 0.0, link
PY
done

# Give up: the headset does not come back within --give-up-after-s: one line, exit status 3.
port=$(free_port)
serve "$port" "$case_dir/calibration" "restart:30s:after=20"
status=$(navigate "$port" giveup --give-up-after-s 0.5)
[ "$status" -eq 3 ] || fail "give-up: navigate exited with $status, not 3"
peer="tofnav navigate: hl2ss://127\.0\.0\.1:$port: "
expect_lines giveup "${peer}the headset closed the stream after 20 frames; reconnecting" \
  "${peer}$refused" "${peer}gave up after 0\.5 s without frames"

# Another device answers on the same address (another calibration): refused, exit status 3.
cp -r "$case_dir/calibration" "$scratch/other"
$python -c 'import sys; p = sys.argv[1]; b = bytearray(open(p, "rb").read()); b[100] ^= 0xFF; open(p, "wb").write(b)' \
  "$(find "$scratch/other" -name uv2xy.bin)"
port=$(free_port)
serve "$port" "$case_dir/calibration" "restart:30s:after=20"
(
  sleep 1.5
  exec "$tofnav" serve "$case_dir/rm_depth_ahat.bin" --calibration "$scratch/other" --port "$port" \
    2>>"$scratch/serve.txt" >/dev/null
) &
servers+=($!)
status=$(navigate "$port" other --give-up-after-s 10)
[ "$status" -eq 3 ] || fail "other device: navigate exited with $status, not 3"
peer="tofnav navigate: hl2ss://127\.0\.0\.1:$port: "
expect_lines other "${peer}the headset closed the stream after 20 frames; reconnecting" "${peer}$refused" \
  "${peer}the device that answered is not the one navigation started with \(its AHAT calibration differs\); stopped: restart tofnav navigate to use it"
echo "live_link_cli_test: ok"
