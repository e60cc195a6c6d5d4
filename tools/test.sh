#!/usr/bin/env bash
# The project's test command (README, .ci/run): every test; the embedding example (a minimal
# engine of its own draws a floor and a head, then the hair into its own targets; validation
# on, and it fails unless the engine's geometry both shows and hides hair); then the library
# as an engine builds it (tools/check_embed.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release
mkdir -p target/embed
cargo run --release --example embed -- --out target/embed/embed.png
bash tools/check_embed.sh
