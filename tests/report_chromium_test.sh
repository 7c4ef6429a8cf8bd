#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The report of the hand-made fixture in headless Chromium: it loads with no console error, every
# figure is present, every PNG decodes and every SVG draws something. Skips (77) without chromium.
# Usage: report_chromium_test.sh <path to tofnav> <fixture demo dir>
set -uo pipefail
tofnav=$1
fixture=$2
browser=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$browser" ]; then
  echo "SKIP: chromium is not installed (scripts/setup.sh installs it)"
  exit 77
fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
fail() {
  echo "FAIL: $*"
  exit 1
}

# The figures of the fixture, every stage having run.
expected='"fig-marker-curve", "fig-depth-histogram", "fig-reconstruction-render", "fig-colour-bar",
  "fig-reconstruction-histogram", "fig-registration-overlay", "fig-tracking-position",
  "fig-tracking-rotation", "fig-guidance-entry", "fig-guidance-angle"'

"$tofnav" report "$fixture" --out "$scratch/report.html" --quiet || fail "tofnav report exited $?"

# A private profile, no display, no GPU, no sandbox (CI runs as root in containers).
run_browser() {  # run_browser <html> <stdout> <stderr>
  HOME="$scratch/home" XDG_CONFIG_HOME="$scratch/home" XDG_CACHE_HOME="$scratch/home" \
    timeout 120 "$browser" --headless --no-sandbox --disable-gpu --disable-dev-shm-usage \
    --no-first-run --disable-extensions --user-data-dir="$scratch/profile" \
    --enable-logging=stderr --v=0 --virtual-time-budget=10000 --dump-dom "file://$1" >"$2" 2>"$3"
}
mkdir -p "$scratch/home"

# 1. The page as written: no console message at all (it has no scripts, so any is an error such
#    as a resource that failed to load).
run_browser "$scratch/report.html" "$scratch/dom.html" "$scratch/log.txt" ||
  fail "chromium exited $? on the report; log:$(tail -20 "$scratch/log.txt")"
grep -q "<h1>tofnav evaluation report</h1>" "$scratch/dom.html" || fail "chromium did not dump the report"
if grep -E ':CONSOLE|Uncaught|Failed to load resource' "$scratch/log.txt"; then
  fail "console messages while loading the report"
fi

# 2. A copy with a checker at the top of <head>: it records errors, then on load inspects every
#    figure and writes its verdict into the DOM that --dump-dom prints.
cat >"$scratch/check.js" <<JS
<script>
(function () {
  const errors = [];
  window.addEventListener('error', (e) => errors.push('error: ' + (e.message || e.target)), true);
  const consoleError = console.error;
  console.error = (...args) => { errors.push('console.error: ' + args.join(' ')); consoleError(...args); };
  window.addEventListener('load', () => {
    const expected = [$expected];
    const problems = [];
    for (const id of expected) {
      const figure = document.getElementById(id);
      if (!figure || figure.tagName !== 'FIGURE') { problems.push('missing ' + id); continue; }
      const images = figure.querySelectorAll('img');
      const plots = figure.querySelectorAll('svg');
      if (images.length + plots.length === 0) problems.push('empty ' + id);
      images.forEach((img, i) => {
        if (!img.complete || img.naturalWidth === 0 || img.naturalHeight === 0) {
          problems.push('image ' + i + ' of ' + id + ' did not decode');
        }
      });
      plots.forEach((svg, i) => {
        const box = svg.getBBox();
        if (!(box.width > 0 && box.height > 0) || svg.querySelectorAll('rect, polyline').length === 0) {
          problems.push('plot ' + i + ' of ' + id + ' draws nothing');
        }
      });
    }
    const figures = document.querySelectorAll('figure').length;
    if (figures !== expected.length) problems.push(figures + ' figures, expected ' + expected.length);
    if (document.querySelectorAll('.not-run').length !== 0) problems.push('a stage reads not run');
    const verdict = document.createElement('pre');
    verdict.id = 'report-check';
    const all = problems.concat(errors);
    verdict.textContent = all.length ? 'REPORT-CHECK FAIL: ' + all.join('; ')
                                     : 'REPORT-CHECK OK ' + figures + ' figures';
    document.body.appendChild(verdict);
  });
})();
</script>
JS
sed -e "/<head>/r $scratch/check.js" "$scratch/report.html" >"$scratch/checked.html"
run_browser "$scratch/checked.html" "$scratch/checked_dom.html" "$scratch/checked_log.txt" ||
  fail "chromium exited $? on the checked copy"
verdict=$(grep -o '<pre id="report-check">[^<]*' "$scratch/checked_dom.html" | sed 's/.*">//' || true)
echo "$verdict"
case "$verdict" in
  "REPORT-CHECK OK"*) ;;
  *) fail "in-page check: ${verdict:-no verdict (the load handler did not run)}" ;;
esac
if grep -E ':CONSOLE|Uncaught' "$scratch/checked_log.txt"; then
  fail "console messages in the checked copy"
fi
echo "PASS: report loads in $("$browser" --version 2>/dev/null | head -1) with every figure"
