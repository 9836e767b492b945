#!/usr/bin/env bash
# Cargo runner for thumbv7em-none-eabihf: runs an ELF in QEMU's mps2-an386 (Cortex-M4F) and
# decodes its defmt log. Exit status: QEMU's (semihosting exit code), 124 on timeout (a hang).
#
#   QEMU_TIMEOUT   seconds before a run counts as hung (default 120)
#   QEMU_SERIAL    QEMU -serial argument for UART0, the navigation link (default: none)
set -uo pipefail
elf="$1"
shift
command -v qemu-system-arm >/dev/null || { echo "qemu-system-arm not found (see .ci/run)" >&2; exit 127; }
command -v defmt-print >/dev/null || { echo "defmt-print not found: cargo install defmt-print --locked" >&2; exit 127; }
# --foreground: stay in the caller's process group, so that stopping the runner stops QEMU.
timeout --foreground "${QEMU_TIMEOUT:-120}" qemu-system-arm \
  -machine mps2-an386 -cpu cortex-m4 \
  -nographic -monitor none -serial "${QEMU_SERIAL:-none}" \
  -semihosting-config enable=on,target=native \
  -icount shift=0 \
  -kernel "$elf" "$@" \
  | defmt-print -e "$elf"
status=("${PIPESTATUS[@]}")
if [ "${status[0]}" -eq 124 ]; then
  echo "qemu-run: TIMEOUT after ${QEMU_TIMEOUT:-120} s (firmware hang)" >&2
fi
exit "${status[0]}"
