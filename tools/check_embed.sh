#!/usr/bin/env bash
# The library as an engine embeds it: built without the default `window` feature, with no
# windowing toolkit or UI crate in its dependency tree (issue 27). Run by tools/test.sh after the
# tests.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --lib --no-default-features
found=$(cargo tree --no-default-features --edges normal --prefix none \
    | grep -E '^(winit|egui|egui-winit|egui-ash-renderer|ash-window|raw-window-handle) ' \
    | sort -u || true)
if [ -n "$found" ]; then
    echo "check_embed: the library without default features still depends on:" >&2
    echo "$found" >&2
    exit 1
fi
echo "check_embed: the library builds without winit, egui or window handles"
