#!/usr/bin/env bash
# Installs what the tests need on a fresh Debian bookworm machine; does nothing that is
# already there. The first step of `cargo xtask ci` (xtask/src/steps.rs).
#  - rustup: the toolchain, rustfmt, clippy and the thumbv7em-none-eabihf target
#  - Debian: fontconfig + a font (host-sim's plots), qemu-system-arm from bookworm-backports
#    (QEMU 10 with mps2-an386; plain bookworm's 7.2 would remove the image's qemu-utils)
#  - Debian: slurm-wlm and munge (the CI's single-node Slurm cluster on localhost that runs
#    deploy/slurm/campaign.sbatch: deploy/slurm/ci/run.sh); installed, not started (the
#    packages' services are left stopped; run.sh starts its own daemons and stops them)
#  - cargo: defmt-print (decodes the firmware's defmt log)
#  - pip: mcap (the official MCAP reader the flight-log tests read host-sim's logs with:
#    host-sim/tests/flight_log.rs, docs/logs.md)
set -euo pipefail
cd "$(dirname "$0")/.."

rustup show active-toolchain >/dev/null
rustup component add rustfmt clippy >/dev/null 2>&1
rustup target add thumbv7em-none-eabihf >/dev/null 2>&1

SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
need=()
for pkg in libfontconfig1-dev fonts-dejavu-core slurm-wlm munge python3-pip; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if ! command -v qemu-system-arm >/dev/null || ! qemu-system-arm -machine help | grep -q mps2-an386; then
  if [ ! -f /etc/apt/sources.list.d/bookworm-backports.sources ]; then
    uris=$(awk '/^URIs:/ { print $2; exit }' /etc/apt/sources.list.d/debian.sources 2>/dev/null || true)
    uris=${uris:-http://deb.debian.org/debian}
    printf 'Types: deb\nURIs: %s\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' "$uris" \
      | $SUDO tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null
  fi
  qemu=1
fi
if [ "${#need[@]}" -gt 0 ] || [ "${qemu:-0}" = 1 ]; then
  $SUDO apt-get update -qq
  [ "${#need[@]}" -gt 0 ] && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${need[@]}"
  [ "${qemu:-0}" = 1 ] && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq -t bookworm-backports qemu-system-arm
fi
command -v defmt-print >/dev/null || cargo install defmt-print --locked
# Debian's python3 refuses a system-wide pip install (PEP 668) unless told to.
python3 -c 'import mcap' 2>/dev/null || python3 -m pip install --quiet mcap 2>/dev/null \
  || python3 -m pip install --quiet --break-system-packages mcap
echo "setup: $(qemu-system-arm --version | head -1); $(defmt-print --version 2>/dev/null | head -1)"
