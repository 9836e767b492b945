#!/usr/bin/env bash
# The firmware's CI: builds both boards, runs the QEMU self-test with each math backend,
# compares its decoded defmt log and the flash/RAM sizes with the snapshots, and proves that a
# wrong answer, a panic, a HardFault and a hang each fail visibly.
#
#   UPDATE_SNAPSHOTS=1 bash scripts/firmware-ci.sh   # rewrite firmware/snapshots/*
set -uo pipefail
cd "$(dirname "$0")/.."
target=thumbv7em-none-eabihf
elf=target/$target/release/firmware-qemu-selftest
snap=firmware/snapshots
flash_budget=$((128 * 1024))
ram_budget=$((32 * 1024))
fail=0
say() { printf '%s\n' "$*"; }
bad() { say "FIRMWARE CI FAILURE: $*"; fail=1; }

# Lines whose numbers depend on the compiler (instruction counts, stack depth) are compared
# with their digits masked; every other line must match exactly. Budgets check the numbers.
normalise() { sed -E '/instructions|stack high-water/ s/[0-9]+/#/g' "$1"; }

for backend in libm micromath; do
  feats=qemu
  [ "$backend" = micromath ] && feats=qemu,micromath
  say "== self-test image, $backend backend"
  cargo build --release -p firmware --target $target --features "$feats" --bin firmware-qemu-selftest || { bad "build ($backend)"; continue; }
  log=$(mktemp)
  QEMU_TIMEOUT=120 bash scripts/qemu-run.sh "$elf" >"$log" 2>&1
  status=$?
  cat "$log"
  [ "$status" -eq 0 ] || bad "self-test ($backend) exited $status"
  grep -q "^INFO  update instructions: max=" "$log" || bad "no instruction count line ($backend)"
  sizes=$(bash scripts/firmware-size.sh "$elf")
  say "sizes ($backend): $sizes"
  flash=${sizes#flash=}; flash=${flash%% *}; ram=${sizes##*ram=}
  [ "$flash" -le "$flash_budget" ] || bad "flash $flash > budget $flash_budget ($backend)"
  [ "$ram" -le "$ram_budget" ] || bad "static RAM $ram > budget $ram_budget ($backend)"
  if [ "${UPDATE_SNAPSHOTS:-0}" = 1 ]; then
    mkdir -p "$snap"
    cp "$log" "$snap/selftest-$backend.log"
    echo "$sizes" > "$snap/size-$backend.txt"
  else
    if ! diff -u <(normalise "$snap/selftest-$backend.log") <(normalise "$log"); then
      bad "defmt log differs from $snap/selftest-$backend.log (UPDATE_SNAPSHOTS=1 to accept)"
    fi
    read -r snapped < "$snap/size-$backend.txt"
    sf=${snapped#flash=}; sf=${sf%% *}
    # ±10 % around the snapshot: a size jump is a review item, not noise.
    if [ $((flash * 10)) -gt $((sf * 11)) ] || [ $((flash * 10)) -lt $((sf * 9)) ]; then
      bad "flash $flash is more than 10 % from the snapshot $sf ($backend)"
    fi
  fi
  if [ "$backend" = libm ]; then
    say "== failure injection: each must fail visibly"
    for inj in wrong panic hardfault hang; do
      QEMU_TIMEOUT=15 bash scripts/qemu-run.sh "$elf" -append "inject=$inj" >"$log" 2>&1
      s=$?
      say "inject=$inj → exit $s: $(grep -E 'ERROR|TIMEOUT' "$log" | head -1)"
      [ "$s" -ne 0 ] || bad "inject=$inj did not fail"
    done
  fi
  rm -f "$log"
done

say "== flying image (QEMU board) and the STM32F405 board"
cargo build --release -p firmware --target $target --features qemu --bins || bad "QEMU board build"
say "QEMU board sizes: $(bash scripts/firmware-size.sh target/$target/release/firmware-qemu)"
stm32=target/$target/release/firmware-stm32f405
cargo build --release -p firmware --target $target --features stm32f405 --bin firmware-stm32f405 || bad "STM32F405 build"
say "STM32F405 sizes: $(bash scripts/firmware-size.sh "$stm32")"
# The STM32 image must be linked with its own memory map (flash at 0x0800_0000, 128 KiB RAM).
reset=$(readelf -s "$stm32" | awk '$8 == "__RESET_VECTOR" { print $2 }')
stack=$(readelf -s "$stm32" | awk '$8 == "_stack_start" { print $2 }')
say "STM32F405 reset vector at 0x$reset, stack top 0x$stack"
[ "$reset" = 08000004 ] && [ "$stack" = 20020000 ] || bad "STM32F405 image linked with the wrong memory map"

say "== processor in the loop: a short mission (PIL must equal SIL) and a link-fault case"
cargo build --release -p host-sim || bad "host-sim build"
pil=target/release/host-sim
out=$(mktemp -d)
if $pil pil --scenario host-sim/scenarios/lawn-mower-20x10.toml --duration 10 --json --out "$out/short" > "$out/short.json"; then
  python3 -c "import json,sys; c=json.load(open('$out/short.json'))['cases'][0]; print('PIL max path %.5f m, SIL %.5f m, %.0f frames/s, worst update %d instructions' % (c['max_path'], c['sil_max_path'], c['pil']['frames_per_second'], c['pil']['worst_update_instructions']))"
else
  bad "PIL short mission (PIL differs from SIL by more than 1 mm, or diverged)"
fi
if $pil pil --scenario host-sim/scenarios/circular-10R.toml --duration 8 --json --out "$out/faults" \
     --drop 100..101 --corrupt 150..152 --delay 200..210 --silent 300..310 > "$out/faults.json"; then
  python3 - "$out/faults.json" <<'PY' || bad "link-fault case: fail-safe not entered and left as expected"
import json, sys
c = json.load(open(sys.argv[1]))["cases"][0]
ev = c["pil"]["failsafe_events"]
print("fail-safe events:", [(e["kind"], e["tick"], e["reason"]) for e in ev], "rx_errors", c["pil"]["board_rx_errors"])
# Silent from tick 300: the third period without a frame (tick 302) is fail-safe; the re-arm
# at tick 310 (first healthy frame) brings it back. Drop/corrupt/delay stay within 2 periods.
assert [e["kind"] for e in ev] == ["enter", "exit"], ev
assert ev[0]["tick"] == 302 and ev[0]["reason"] == "stale state", ev
assert ev[1]["tick"] == 310, ev
assert c["pil"]["board_rx_errors"] >= 2
PY
else
  bad "PIL link-fault case failed to run"
fi
rm -rf "$out"

if [ "$fail" -ne 0 ]; then
  say "firmware CI: FAILED"
  exit 1
fi
say "firmware CI: passed"
