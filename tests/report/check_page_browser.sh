#!/bin/sh
# Opens an HTML page of the project (the report, or a compare page) in real
# headless Chromium and checks that it renders, that every image on it loads
# (embedded or a file), that every local link (data files) points at a file
# that exists, and that the browser logged no console error.
#
# Usage: check_page_browser.sh PAGE.html
# Exit 0 when all hold; 1 naming each problem otherwise; 2 on bad usage or
# when Chromium is missing (scripts/install-deps.sh installs it).
set -u
page="${1:-}"
[ -n "$page" ] && [ -f "$page" ] || { echo "usage: $0 PAGE.html (got '${page}': no such file)" >&2; exit 2; }
CHROMIUM="${CHROMIUM:-/usr/bin/chromium}"
[ -x "$CHROMIUM" ] || { echo "$0: $CHROMIUM not found: run scripts/install-deps.sh (Debian package chromium)" >&2; exit 2; }

page=$(cd "$(dirname "$page")" && pwd)/$(basename "$page")
dir=$(dirname "$page")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0

# 1. Local links: every href that is not a web address, an anchor or a data
#    URI must name a file that exists (relative to the page).
grep -o 'href="[^"]*"' "$page" | sed 's/^href="//; s/"$//' | while IFS= read -r ref; do
  case "$ref" in http:*|https:*|mailto:*|\#*|data:*|'') continue ;; esac
  target=$(printf '%s' "$ref" | sed 's/#.*//; s/&amp;/\&/g')
  case "$target" in /*) f="$target" ;; *) f="$dir/$target" ;; esac
  [ -e "$f" ] || echo "missing link target: $ref"
done > "$work/links.txt"
if [ -s "$work/links.txt" ]; then cat "$work/links.txt"; fail=1; fi

# 2. Render a copy of the page beside it (relative paths stay valid) with a
#    probe that, once everything has loaded, lists the images that did not.
probe="$dir/.browser_check_$$.html"
trap 'rm -rf "$work" "$probe"' EXIT
sed 's|</body>|<script>window.addEventListener("load",function(){var b=[],im=document.images;for(var i=0;i<im.length;i++){if(!im[i].complete\|\|im[i].naturalWidth===0)b.push(im[i].alt\|\|im[i].src.slice(0,80));}var p=document.createElement("pre");p.id="mill-check";p.textContent="MILL-CHECK images="+im.length+" broken="+b.length+(b.length?" :: "+b.join(" \| "):"");document.body.appendChild(p);});</script></body>|' \
  "$page" > "$probe"
grep -q 'MILL-CHECK' "$probe" || { echo "$page: no </body> to attach the check to"; exit 1; }
timeout 120 "$CHROMIUM" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
  --disable-background-networking --disable-component-update --disable-sync \
  --user-data-dir="$work/profile" --enable-logging=stderr --v=0 --virtual-time-budget=10000 \
  --dump-dom "file://$probe" > "$work/dom.html" 2> "$work/console.txt"
status=$?
if [ $status -ne 0 ]; then
  echo "chromium exited with status $status:"; tail -5 "$work/console.txt"; exit 1
fi
result=$(grep -o 'MILL-CHECK images=[0-9]* broken=[0-9]*[^<]*' "$work/dom.html" | tail -1)
if [ -z "$result" ]; then
  echo "the page did not finish loading (no check result in the rendered DOM)"; fail=1
else
  echo "$result"
  case "$result" in *" broken=0"*) ;; *) echo "images that did not load: ${result#* :: }"; fail=1 ;; esac
  case "$result" in *"images=0 "*) echo "no image on the page"; fail=1 ;; esac
fi
grep -q '<h1>' "$work/dom.html" || { echo "no <h1> in the rendered page"; fail=1; }

# 3. Console: uncaught script errors and failed loads the page caused.
if grep -E 'CONSOLE|Uncaught' "$work/console.txt" | grep -E 'Uncaught|Error|ERROR|Failed to load|Not allowed' > "$work/errors.txt"; then
  echo "console errors:"; cat "$work/errors.txt"; fail=1
fi
[ $fail -eq 0 ] && echo "ok: $page renders, every image loads, every linked file exists, no console error"
exit $fail
