#!/usr/bin/env bash
# Every test of the workspace: host tests (both math backends of the core), the
# thumbv7em-none-eabihf cross-builds. Set-up included: safe to run on a fresh machine.
set -euo pipefail
cd "$(dirname "$0")/.."

# rust-toolchain.toml pins stable + the thumbv7em target; make sure both are present.
rustup target add thumbv7em-none-eabihf >/dev/null

echo "== host tests (libm backend): controller-core, host-sim (plant, scenarios, CLI), closed loop"
cargo test --workspace --release

echo "== controller-core tests with the micromath backend"
cargo test -p controller-core --release --features micromath

echo "== cross-build for thumbv7em-none-eabihf"
cargo build -p controller-core --release --target thumbv7em-none-eabihf
cargo build -p controller-core --release --target thumbv7em-none-eabihf --features micromath
cargo build -p firmware --release --target thumbv7em-none-eabihf

echo "all tests passed"
