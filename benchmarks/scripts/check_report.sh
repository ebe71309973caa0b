#!/usr/bin/env bash
# Checks a sweep report as a reader would see it:
#   benchmarks/scripts/check_report.sh DIR [SCREENSHOT.png]
# 1. every <img src> of DIR/index.html exists on disk (fails listing the
#    missing ones);
# 2. headless Chromium opens DIR/index.html and saves a screenshot
#    (default DIR/screenshot.png), which must be a non-empty PNG.
# Needs Debian's chromium package (apt-get install -y chromium).
set -euo pipefail

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
    echo "usage: $0 DIR [SCREENSHOT.png]" >&2
    exit 2
fi
dir=$(cd "$1" && pwd)
out=${2:-$dir/screenshot.png}
html=$dir/index.html
if [ ! -f "$html" ]; then
    echo "no report: $html does not exist" >&2
    exit 1
fi

# 1. Images: every src="..." of an <img> (HTML entities decoded), relative
#    to DIR unless absolute.
decode() {
    sed -e 's/&#x2[fF];/\//g' -e 's/&#x27;/'"'"'/g' -e 's/&#39;/'"'"'/g' \
        -e 's/&quot;/"/g' -e 's/&lt;/</g' -e 's/&gt;/>/g' -e 's/&amp;/\&/g'
}
missing=0
count=0
while IFS= read -r src; do
    [ -z "$src" ] && continue
    count=$((count + 1))
    case "$src" in
        /*) path=$src ;;
        file://*) path=${src#file://} ;;
        *) path=$dir/$src ;;
    esac
    if [ ! -s "$path" ]; then
        echo "missing image: $src" >&2
        missing=$((missing + 1))
    fi
done < <(grep -o '<img [^>]*src="[^"]*"' "$html" | sed 's/.*src="\([^"]*\)"/\1/' | decode)
if [ "$missing" -gt 0 ]; then
    echo "$missing of $count images of $html are missing" >&2
    exit 1
fi
echo "$count images, all present"

# 2. Screenshot.
chromium=${CHROMIUM:-/usr/bin/chromium}
if [ ! -x "$chromium" ]; then
    echo "headless Chromium not found at $chromium; install it with: apt-get install -y chromium" >&2
    exit 1
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
rm -f "$out"
"$chromium" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$profile" --hide-scrollbars --screenshot="$out" \
    --window-size=1280,2400 "file://$html" >"$profile/chromium.log" 2>&1 || {
    cat "$profile/chromium.log" >&2
    echo "chromium failed" >&2
    exit 1
}
if [ ! -s "$out" ] || [ "$(head -c 8 "$out" | od -An -tx1 | tr -d ' \n')" != "89504e470d0a1a0a" ]; then
    cat "$profile/chromium.log" >&2
    echo "no screenshot written to $out" >&2
    exit 1
fi
echo "screenshot: $out"
