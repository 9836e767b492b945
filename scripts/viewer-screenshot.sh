#!/usr/bin/env bash
# A screenshot of a flight log in Foxglove Studio with a shipped layout, made by the real
# viewer: the open-source Foxglove Studio's app core (@foxglove/studio-base, a prebuilt bundle
# on npm) served on localhost around the web app's root (scripts/viewer-screenshot/), driven in
# headless Chromium by playwright-core as a user would: "Open local file" -> the log, then
# "Layouts -> Import from file" -> the layout (docs/logs.md#layouts). Fails, naming them, if
# Foxglove reports a problem with the log (Choice 482).
#
# usage: scripts/viewer-screenshot.sh LOG.mcap [LAYOUT.json] [OUT.png]
#   LAYOUT  default layouts/auv150.foxglove.json
#   OUT     default docs/images/foxglove-views.png
#   CHROMIUM=path  the browser (default /usr/bin/chromium: Debian's `chromium` package)
#   VIEWER_DIR=dir where the viewer is installed from npm (default: a new temporary folder,
#                  removed at the end); nothing of it enters the repository.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
usage="usage: scripts/viewer-screenshot.sh LOG.mcap [LAYOUT.json] [OUT.png]"
log=${1:?$usage}
layout=${2:-$root/layouts/auv150.foxglove.json}
out=${3:-$root/docs/images/foxglove-views.png}
chromium=${CHROMIUM:-/usr/bin/chromium}

# The versions the README's picture was made with.
STUDIO_BASE=1.48.0 # the last @foxglove/studio-base on npm (Foxglove Studio 1.48, MPL-2.0)
REACT=17.0.2       # the React it was built against (its devDependencies)
PLAYWRIGHT=1.65.2
UPNG=2.1.0 # the screenshot's palette

for f in "$log" "$layout"; do
    [ -f "$f" ] || { echo "viewer-screenshot: no file $f" >&2; exit 2; }
done
[ -x "$chromium" ] || {
    echo "viewer-screenshot: no browser at $chromium (apt-get install chromium, or set CHROMIUM)" >&2
    exit 2
}
command -v npm >/dev/null || { echo "viewer-screenshot: needs node and npm" >&2; exit 2; }
out=$(cd "$(dirname "$out")" && pwd)/$(basename "$out")

if [ -n "${VIEWER_DIR:-}" ]; then
    work=$VIEWER_DIR
    mkdir -p "$work"
else
    work=$(mktemp -d)
fi
server=
cleanup() {
    [ -z "$server" ] || kill "$server" 2>/dev/null || true
    [ -n "${VIEWER_DIR:-}" ] || rm -rf "$work"
}
trap cleanup EXIT

echo "viewer-screenshot: installing the viewer from npm into $work"
(
    cd "$work"
    [ -f package.json ] || npm init -y >/dev/null
    npm install --no-audit --no-fund --loglevel=error \
        "@foxglove/studio-base@$STUDIO_BASE" "react@$REACT" "react-dom@$REACT" \
        "playwright-core@$PLAYWRIGHT" "upng-js@$UPNG" >/dev/null
)

site=$work/site
rm -rf "$site"
mkdir -p "$site"
cp "$root"/scripts/viewer-screenshot/index.html "$root"/scripts/viewer-screenshot/main.js "$site"/
cp "$work"/node_modules/react/umd/react.production.min.js \
    "$work"/node_modules/react-dom/umd/react-dom.production.min.js "$site"/
ln -s "$work"/node_modules/@foxglove/studio-base "$site"/studio-base
cp "$log" "$layout" "$site"/
# Beside its node_modules, so that it finds playwright-core.
cp "$root"/scripts/viewer-screenshot/shoot.mjs "$work"/

port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 -m http.server "$port" --bind 127.0.0.1 --directory "$site" >"$work"/http.log 2>&1 &
server=$!
for _ in $(seq 50); do
    curl -sf "http://127.0.0.1:$port/index.html" >/dev/null && break
    sleep 0.2
done

echo "viewer-screenshot: Foxglove Studio $STUDIO_BASE on http://127.0.0.1:$port, $(basename "$log") with $(basename "$layout")"
CHROMIUM=$chromium node "$work"/shoot.mjs "http://127.0.0.1:$port" \
    "$(basename "$log")" "$(basename "$layout")" "$out"
