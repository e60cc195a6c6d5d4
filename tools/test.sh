#!/usr/bin/env bash
# The project's test command (README, .ci/run): every test, then the library as an engine
# embeds it (tools/check_embed.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release
bash tools/check_embed.sh
