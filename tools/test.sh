#!/usr/bin/env bash
# The project's test command (README, .ci/run): every test; the embedding example (a minimal
# engine of its own draws a floor and a head, then the hair into its own targets; validation
# on, and it fails unless the engine's geometry both shows and hides about as much hair as
# measured); then the library as an engine builds it (tools/check_embed.sh); then the Bevy
# plugin's example, headless.
#
# `tools/test.sh --quick` is the edit-compile loop (not CI): the unit tests, the CPU oracle
# and one frame per generation path against each other (see src/guide/testing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ "${1:-}" == "--quick" ]]; then
    cargo test --release --lib
    cargo test --release --test generator
    cargo test --release --test lod_and_mesh_path mesh_path_matches_compute_path
    exit 0
fi
cargo test --release
mkdir -p target/embed
cargo run --release --example embed -- --out target/embed/embed.png
bash tools/check_embed.sh
# The Bevy plugin's example: headless, validation on; it fails unless Bevy's frame shows and
# hides about as much hair as measured (src/guide/bevy.md).
cargo test --release -p hairmesh-bevy
cargo run --release -p hairmesh-bevy --example crowd -- --headless --out target/bevy
