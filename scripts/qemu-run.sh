#!/usr/bin/env bash
# Cargo runner for thumbv7em-none-eabihf: runs an ELF in QEMU and decodes its defmt log. Exit
# status: QEMU's (semihosting exit code), 124 on timeout (a hang), 2 for an image QEMU cannot run.
#
# The machine comes from the image's marker (firmware/images/src/image.rs, Image::qemu_machine; a host
# test checks that this script agrees): mps2-an386 (Cortex-M4F, the link on UART0, the first
# -serial) for the QEMU images, netduinoplus2 (STM32F405, the link on USART2, the second
# -serial) for the STM32 emulator build.
#
#   QEMU_TIMEOUT   seconds before a run counts as hung (default 120)
#   QEMU_SERIAL    QEMU -serial argument for the navigation link's UART (default: none);
#                  `pty` puts it on a pseudo-terminal, named on stderr as
#                  `qemu-run: UART0 on pty /dev/pts/N` (USART2 on netduinoplus2):
#                  `host-sim hil --port` opens it (QEMU's own `char device redirected to` line
#                  goes to stdout, into defmt-print)
#   QEMU_PTY_LINK  with QEMU_SERIAL=pty: a symlink QEMU makes to the pty (default: a fresh
#                  name under /tmp); it is removed when QEMU ends
#   QEMU_ICOUNT    QEMU -icount argument (default shift=0: 1 instruction = 1 ns, deterministic
#                  timings); `off` runs without it, so that the board's SysTick follows the
#                  wall clock (`host-sim hil --pacing realtime` against QEMU)
set -uo pipefail
elf="$1"
shift
marker=$(grep -ao 'auv150-image:[a-z0-9-]*;' "$elf" 2>/dev/null | head -1)
bin=${marker#auv150-image:}
bin=${bin%;}
case "$bin" in
  firmware-stm32f405-emulator) machine=netduinoplus2 uart=USART2 before=(-serial null) ;;
  firmware-stm32f405)
    echo "qemu-run: $elf is the STM32F405 flight image: it does not run under QEMU (no clock tree: it waits for the crystal forever); run firmware-stm32f405-emulator" >&2
    exit 2 ;;
  *) machine=mps2-an386 uart=UART0 before=() ;;
esac
icount=(-icount "${QEMU_ICOUNT:-shift=0}")
if [ "${QEMU_ICOUNT:-}" = off ]; then icount=(); fi
serial=("${before[@]}" -serial "${QEMU_SERIAL:-none}")
if [ "${QEMU_SERIAL:-}" = pty ]; then
  link="${QEMU_PTY_LINK:-$(mktemp -u /tmp/qemu-uart0.XXXXXX)}"
  serial=(-chardev "pty,id=link,path=$link" "${before[@]}" -serial chardev:link)
  # Name the pty on stderr once QEMU has made it (at most 30 s).
  (for _ in $(seq 300); do
     if [ -L "$link" ]; then echo "qemu-run: $uart on pty $(readlink "$link") ($link)" >&2; exit 0; fi
     sleep 0.1
   done) &
fi
command -v qemu-system-arm >/dev/null || { echo "qemu-system-arm not found (bash scripts/setup.sh installs it)" >&2; exit 127; }
command -v defmt-print >/dev/null || { echo "defmt-print not found: cargo install defmt-print --locked" >&2; exit 127; }
# --foreground: stay in the caller's process group, so that stopping the runner stops QEMU.
timeout --foreground "${QEMU_TIMEOUT:-120}" qemu-system-arm \
  -machine "$machine" -cpu cortex-m4 \
  -nographic -monitor none "${serial[@]}" \
  -semihosting-config enable=on,target=native \
  "${icount[@]}" \
  -kernel "$elf" "$@" \
  | defmt-print -e "$elf"
status=("${PIPESTATUS[@]}")
if [ "${status[0]}" -eq 124 ]; then
  echo "qemu-run: TIMEOUT after ${QEMU_TIMEOUT:-120} s (firmware hang)" >&2
fi
exit "${status[0]}"
