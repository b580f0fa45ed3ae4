#!/bin/sh
# check_page_browser.sh on a small hand-made page (no engine run needed): it
# passes with its figure file and data file present, and fails, naming the
# figure, once the figure file is deleted; likewise for a script error.
#
# Usage: test_check_page.sh PNG   (any PNG, copied in as the page's figure)
set -u
check="$(cd "$(dirname "$0")" && pwd)/check_page_browser.sh"
[ -f "${1:-}" ] || { echo "usage: $0 PNG" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$1" "$work/figure.png"
echo "size_mm,passing_percent" > "$work/data.csv"
cat > "$work/page.html" <<'HTML'
<!DOCTYPE html><html><head><meta charset="utf-8"><title>t</title></head><body><h1>A page</h1>
<figure><img alt="the figure" src="figure.png"><figcaption>the figure</figcaption></figure>
<p>Data: <a href="data.csv">data.csv</a>, <a href="#top">top</a>, <a href="https://example.org/">web</a></p>
</body></html>
HTML
status=0
"$check" "$work/page.html" || { echo "FAIL: the intact page does not pass"; status=1; }
rm "$work/figure.png"
if "$check" "$work/page.html" > "$work/log" 2>&1 || ! grep -q "did not load: the figure" "$work/log"; then
  cat "$work/log"; echo "FAIL: a deleted figure file was not caught"; status=1
fi
cp "$1" "$work/figure.png"
sed 's|</h1>|</h1><script>notDefined()</script>|' "$work/page.html" > "$work/script.html"
if "$check" "$work/script.html" > "$work/log" 2>&1 || ! grep -q "Uncaught" "$work/log"; then
  cat "$work/log"; echo "FAIL: a script error was not caught"; status=1
fi
[ $status -eq 0 ] && echo "ok"
exit $status
