#!/usr/bin/env bash
# Opens a `shadowbake report` page (DIR/index.html) in headless Chromium and checks that it loads:
# every <img> decoded (the page's own script sets data-images-ok="yes" on <body>), no uncaught
# script error, every src="..." is a file in DIR, nothing is fetched from elsewhere. Saves
# DIR/screenshot.png (1400 × 2000) to look at. Exits 0 if all is well, else 1 with a message.
# Usage: tests/tools/check_report_page.sh DIR     (CHROMIUM overrides /usr/bin/chromium)
set -euo pipefail

fail() {
  echo "check_report_page: $*" >&2
  exit 1
}

[[ $# -eq 1 ]] || fail "usage: $0 REPORT_DIR"
[[ -d $1 ]] || fail "$1: no such folder"
dir=$(cd "$1" && pwd)
page="$dir/index.html"
[[ -f $page ]] || fail "$page: no such file"
chromium=${CHROMIUM:-/usr/bin/chromium}
[[ -x $chromium ]] || fail "$chromium: not found (apt-get install chromium)"

scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

flags=(--headless --no-sandbox --disable-gpu --disable-quic --no-first-run
  --disable-background-networking --disable-component-update --disable-sync
  --virtual-time-budget=5000 --enable-logging=stderr --v=0)

# (a) the DOM after the load event: the page's image check must have said yes.
if ! timeout 120 "$chromium" "${flags[@]}" --user-data-dir="$(mktemp -d -p "$scratch")" \
  --dump-dom "file://$page" >"$scratch/dom.html" 2>"$scratch/dom.log"; then
  tail -5 "$scratch/dom.log" >&2
  fail "chromium --dump-dom failed on $page"
fi
if ! grep -q 'data-images-ok="yes"' "$scratch/dom.html"; then
  verdict=$(grep -o 'data-images-ok="[^"]*"' "$scratch/dom.html" || true)
  fail "$page: images did not all load: ${verdict:-no verdict, the image check script did not run}"
fi
if grep -E 'Uncaught|CONSOLE.*(Error|error)' "$scratch/dom.log" >&2; then
  fail "$page: script errors while loading (above)"
fi

# (b) a screenshot, to look at.
rm -f "$dir/screenshot.png"
if ! timeout 120 "$chromium" "${flags[@]}" --user-data-dir="$(mktemp -d -p "$scratch")" \
  --screenshot="$dir/screenshot.png" --window-size=1400,2000 "file://$page" \
  >"$scratch/shot.log" 2>&1; then
  tail -5 "$scratch/shot.log" >&2
  fail "chromium --screenshot failed on $page"
fi
[[ -s $dir/screenshot.png ]] || fail "$dir/screenshot.png: not written"

# (c) every referenced file exists in DIR, and nothing comes from elsewhere.
missing=()
while IFS= read -r src; do
  case $src in
    http:* | https:* | //* | file:* | /*) fail "$page: refers outside its folder: $src" ;;
  esac
  [[ -f "$dir/$src" ]] || missing+=("$src")
done < <(grep -o 'src="[^"]*"' "$page" | sed -e 's/^src="//' -e 's/"$//')
((${#missing[@]} == 0)) || fail "$page: missing files: ${missing[*]}"
if grep -qiE '<link[^>]+href=|@import|url\(' "$page"; then
  fail "$page: loads a stylesheet or font from elsewhere"
fi
echo "check_report_page: $page: ok ($(grep -o '<img ' "$page" | wc -l) images; screenshot $dir/screenshot.png)"
