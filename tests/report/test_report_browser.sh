#!/bin/sh
# The report page of a finished run in real headless Chromium: it must pass
# check_page_browser.sh, and the check must fail on damaged copies of it (an
# embedded figure whose data is cut, a linked data file deleted), so that the
# check itself is known to catch them.
#
# Usage: test_report_browser.sh RUN_DIR   (a run folder with report/index.html)
set -u
here=$(cd "$(dirname "$0")" && pwd)
check="$here/check_page_browser.sh"
run="${1:-}"
[ -n "$run" ] && [ -f "$run/report/index.html" ] || { echo "usage: $0 RUN_DIR (no report/index.html in '${run}')" >&2; exit 2; }
run=$(cd "$run" && pwd -P)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0

echo "== the report as written"
"$check" "$run/report/index.html" || { echo "FAIL: the report does not pass the browser check"; status=1; }

# A copy of the run whose stage folders are links to the real ones, so that
# the page's relative links resolve; `except` is one file left out of breakage/.
copy_run() {  # copy_run DEST [except]
  mkdir -p "$1/report" "$1/breakage"
  cp "$run/report/index.html" "$1/report/"
  for s in "$run"/*; do
    name=$(basename "$s")
    [ "$name" = report ] || [ "$name" = breakage ] || ln -s "$s" "$1/$name"
  done
  for f in "$run"/breakage/*; do
    [ "$(basename "$f")" = "${2:-}" ] || ln -s "$f" "$1/breakage/"
  done
}

echo "== a copy whose first figure lost most of its data: must fail"
copy_run "$work/cut"
/usr/bin/python3 - "$work/cut/report/index.html" <<'PY'
import sys
path = sys.argv[1]
s = open(path).read()
key = 'src="data:image/png;base64,'
i = s.index(key) + len(key)
j = s.index('"', i)
open(path, "w").write(s[:i] + s[i + 64:i + 128] + s[j:])
PY
if "$check" "$work/cut/report/index.html" > "$work/cut.log" 2>&1; then
  cat "$work/cut.log"; echo "FAIL: a broken figure passed the check"; status=1
elif ! grep -q "did not load" "$work/cut.log"; then
  cat "$work/cut.log"; echo "FAIL: the check failed, but not for the broken figure"; status=1
else
  grep "did not load" "$work/cut.log"
fi

echo "== a copy with breakage/summary.csv deleted: must fail"
grep -q 'href="../breakage/summary.csv"' "$run/report/index.html" || { echo "FAIL: the report links no breakage/summary.csv"; status=1; }
copy_run "$work/nodata" summary.csv
if "$check" "$work/nodata/report/index.html" > "$work/nodata.log" 2>&1; then
  cat "$work/nodata.log"; echo "FAIL: a missing data file passed the check"; status=1
elif ! grep -q "missing link target: ../breakage/summary.csv" "$work/nodata.log"; then
  cat "$work/nodata.log"; echo "FAIL: the check failed, but did not name breakage/summary.csv"; status=1
else
  grep "missing link target" "$work/nodata.log"
fi
[ $status -eq 0 ] && echo "ok"
exit $status
