#!/usr/bin/env bash
# Every test of the workspace: `cargo xtask ci` (xtask/src/steps.rs); this line is for old habits.
exec cargo xtask ci "$@"
