#!/usr/bin/env bash
# The library as an engine embeds it: built without the default `window` feature, with no
# windowing toolkit, UI crate, wgpu or Bevy in its dependency tree (issues 27, 47). Run by tools/test.sh after the
# tests.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -p hairmesh --lib --no-default-features
found=$(cargo tree -p hairmesh --no-default-features --edges normal --prefix none \
    | grep -E '^(winit|egui|egui-winit|egui-ash-renderer|ash-window|raw-window-handle|wgpu|bevy[a-z_]*) ' \
    | sort -u || true)
if [ -n "$found" ]; then
    echo "check_embed: the library without default features still depends on:" >&2
    echo "$found" >&2
    exit 1
fi
echo "check_embed: the library builds without winit, egui, window handles, wgpu or Bevy"
