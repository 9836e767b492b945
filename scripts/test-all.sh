#!/usr/bin/env bash
# Every test of the workspace, set-up included (safe on a fresh machine):
# host tests with the three math backends of the core (kernels, micromath, libm), the simulator and the closed loop, the
# firmware's host tests, and the firmware on the target (`cargo xtask firmware`, xtask/): every
# image built, its memory map and sizes checked, the QEMU self-test (golden vectors,
# instruction counts, fail-safe, snapshots, failure injection) and processor in the loop.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# The STM32 image needs a link key: the public CI test key unless one is given.
source scripts/ci-link-key.sh

echo "== host tests (the kernels math backend, the default): controller-core, link, host-sim (plant, scenarios, CLI), closed loop, firmware logic, xtask"
cargo test --workspace --profile host

echo "== controller-core tests with the micromath backend"
cargo test -p controller-core --profile host --features micromath

echo "== controller-core tests with the libm backend"
cargo test -p controller-core --profile host --features libm-math

echo "== controller-core cross-build for thumbv7em-none-eabihf"
cargo build -p controller-core --release --target thumbv7em-none-eabihf
cargo build -p controller-core --release --target thumbv7em-none-eabihf --features micromath

echo "== firmware on the target: images, QEMU self-test, snapshots, failure injection, PIL"
cargo xtask firmware

echo "all tests passed"
