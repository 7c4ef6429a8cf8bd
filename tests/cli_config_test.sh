#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Configuration files (docs/pipeline.md, "Configuration files"): --print-config writes valid JSON
# with the defaults, reads back to itself through --config, a file's value counts, the command
# line overrides the file, one file serves several commands, and a bad file is one line naming
# it. Also tofnav --version is the CMake project version.
# Usage: cli_config_test.sh <path to tofnav> <project version>
set -uo pipefail
tofnav=$1
version=$2
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
# json_get <file> <python expression on o>: prints the value.
json_get() { /usr/bin/python3 -c "import json,sys; o = json.load(open(sys.argv[1])); print($2)" "$1"; }

commands=(simulate identify correct reconstruct track fit-marker-error tool-define pivot register
  skin navigate verify demo info convert serve report "evaluate suite" "evaluate tracking"
  "evaluate depth" "evaluate reconstruction" "evaluate guidance" "evaluate materials")
for command in "${commands[@]}"; do
  # shellcheck disable=SC2086  # "evaluate suite" is two words
  if ! "$tofnav" $command --print-config >"$scratch/a.json" 2>"$scratch/err"; then
    fail "tofnav $command --print-config: $(cat "$scratch/err")"
    continue
  fi
  /usr/bin/python3 -m json.tool "$scratch/a.json" >/dev/null || fail "$command: not JSON"
  section=$(json_get "$scratch/a.json" 'list(o)[0]')
  [ "$section" = evaluate ] && section="evaluate $(json_get "$scratch/a.json" 'list(o["evaluate"])[0]')"
  [ "$section" = "$command" ] || fail "$command: --print-config is in section '$section'"
  # shellcheck disable=SC2086
  "$tofnav" $command --config "$scratch/a.json" --print-config >"$scratch/b.json" ||
    fail "tofnav $command --config (its own --print-config) failed"
  cmp -s "$scratch/a.json" "$scratch/b.json" || fail "$command: --print-config does not read back"
  # shellcheck disable=SC2086
  # grep reads it all (-q would close the pipe early, and a help over 4 KiB would die of SIGPIPE)
  "$tofnav" $command --help | grep -- "--config" >/dev/null || fail "$command --help lacks --config"
done

# A known default, shown by --print-config and by --help (CLI11's default, not the help text).
"$tofnav" track --print-config >"$scratch/track.json"
[ "$(json_get "$scratch/track.json" 'o["track"]["ab-threshold"]')" = 1280 ] ||
  fail "track --print-config: ab-threshold is not 1280"
[ "$(json_get "$scratch/track.json" 'o["track"]["recording"]')" = None ] ||
  fail "track --print-config: an unset positional is not null"
"$tofnav" track --help | grep -- '--ab-threshold FLOAT=1280' >/dev/null || fail "track --help: no default"

# A value in the file counts; the command line overrides it; flat files and sections both read.
printf '{"track": {"ab-threshold": 900, "tool": ["a.json", "b.json"], "no-filter": true}}' \
  >"$scratch/set.json"
"$tofnav" track --config "$scratch/set.json" --print-config >"$scratch/out.json"
[ "$(json_get "$scratch/out.json" 'o["track"]["ab-threshold"]')" = 900 ] ||
  fail "the file's ab-threshold was not used"
[ "$(json_get "$scratch/out.json" 'o["track"]["tool"]')" = "['a.json', 'b.json']" ] ||
  fail "the file's tool list was not used"
[ "$(json_get "$scratch/out.json" 'o["track"]["no-filter"]')" = True ] || fail "flag from file"
"$tofnav" track --config "$scratch/set.json" --ab-threshold 1000 --print-config >"$scratch/out.json"
[ "$(json_get "$scratch/out.json" 'o["track"]["ab-threshold"]')" = 1000 ] ||
  fail "the command line did not override the file"
printf '{"ab-threshold": 700}' >"$scratch/flat.json"
"$tofnav" track --config "$scratch/flat.json" --print-config >"$scratch/out.json"
[ "$(json_get "$scratch/out.json" 'o["track"]["ab-threshold"]')" = 700 ] || fail "flat file"
# One set-up file for several commands: each reads its section, skips the others'.
printf '{"track": {"ab-threshold": 900}, "identify": {"max-frames": 50}, "evaluate": {"suite": {"frames-scale": 0.5}, "tracking": {"wrong-mm": 5}}}' \
  >"$scratch/setup.json"
"$tofnav" identify --config "$scratch/setup.json" --print-config >"$scratch/out.json" ||
  fail "identify with a set-up file"
[ "$(json_get "$scratch/out.json" 'o["identify"]["max-frames"]')" = 50 ] || fail "identify section"
"$tofnav" evaluate suite --config "$scratch/setup.json" --print-config >"$scratch/out.json" ||
  fail "evaluate suite with a set-up file"
[ "$(json_get "$scratch/out.json" 'o["evaluate"]["suite"]["frames-scale"]')" = 0.5 ] ||
  fail "evaluate suite section"

# Behaviour: simulate renders the file's frame count and records its options in --json.
printf '{"simulate": {"scenario": "marker-stage", "frames": 2, "quiet": true}}' \
  >"$scratch/sim.json"
if "$tofnav" simulate --config "$scratch/sim.json" --out "$scratch/sim" --json >"$scratch/sim_out.json"; then
  [ "$(json_get "$scratch/sim_out.json" 'o["frames"]')" = 2 ] || fail "simulate: frames from file"
  [ "$(json_get "$scratch/sim_out.json" 'o["options"]["frames"]')" = 2 ] ||
    fail "simulate --json lacks the options it ran with"
  [ "$(json_get "$scratch/sim_out.json" 'o["options"]["out"]')" = "$scratch/sim" ] ||
    fail "simulate --json: options.out"
else
  fail "simulate --config"
fi

# Bad files: one line on stderr naming the file (and the key or the position), exit != 0.
expect_config_error() {  # expect_config_error <needle> <file content> <command...>
  local needle=$1 content=$2
  shift 2
  printf '%s' "$content" >"$scratch/bad.json"
  "$tofnav" "$@" --config "$scratch/bad.json" >/dev/null 2>"$scratch/err"
  local rc=$?
  if [ $rc -eq 0 ] || [ $rc -ge 128 ]; then
    fail "tofnav $* with '$content' exited $rc"
  elif [ "$(wc -l <"$scratch/err")" -ne 1 ] || ! grep -qF "$scratch/bad.json" "$scratch/err" ||
    ! grep -qF -- "$needle" "$scratch/err"; then
    fail "tofnav $* with '$content': want one line naming the file and '$needle', got:"
    cat "$scratch/err"
  fi
}
expect_config_error "line 1, column 19" '{"ab-threshold": 9' track --print-config
expect_config_error "unknown option 'ab-treshold'" '{"ab-treshold": 9}' track --print-config
expect_config_error "unknown option 'trak.ab-threshold'" '{"trak": {"ab-threshold": 9}}' track
expect_config_error "key 'tool'" '{"tool": [{"name": "x"}]}' track --print-config
expect_config_error "expected a JSON object" '[1, 2]' track --print-config
expect_config_error "--ab-threshold" '{"ab-threshold": "bright"}' track --print-config
"$tofnav" track --config "$scratch/missing.json" --print-config >/dev/null 2>"$scratch/err" &&
  fail "a missing config file was accepted"
grep -qF "$scratch/missing.json" "$scratch/err" || fail "missing file not named: $(cat "$scratch/err")"

# The version is CMake's project(tofnav VERSION ...).
[ "$("$tofnav" --version)" = "tofnav $version" ] || fail "tofnav --version: $("$tofnav" --version)"
[ "$("$tofnav" track --version)" = "$version" ] || fail "tofnav track --version"

[ $failures -eq 0 ] && echo "all CLI configuration checks passed"
exit $failures
