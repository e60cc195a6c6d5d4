#!/usr/bin/env bash
# One-time machine setup for building and testing (Debian 12 "bookworm"). Idempotent.
#
# Installs: Xvfb (the crowd window test runs under it), Mesa's lavapipe (software Vulkan with VK_EXT_mesh_shader, from bookworm-backports),
# the Vulkan loader and validation layers, Debian's libshaderc (so the shaderc crate links it
# instead of compiling glslang from source), and checks the Rust toolchain.
#
# The backports source is derived from this machine's own Debian source entry (same URIs,
# suite "<codename>-backports"); no mirror is named here.
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

. /etc/os-release
codename="${VERSION_CODENAME:-bookworm}"
backports_list=/etc/apt/sources.list.d/hairmesh-backports.sources

# First Debian (non-security) URI of the machine's configured sources.
debian_uri() {
    local f
    for f in /etc/apt/sources.list.d/*.sources; do
        [ -f "$f" ] || continue
        # deb822 stanzas: take URIs of a stanza whose Suites contain the plain codename.
        awk -v c="$codename" '
            /^URIs:/ { uris=$2 }
            /^Suites:/ { for (i=2;i<=NF;i++) if ($i==c) found=uris }
            /^$/ { uris="" }
            END { if (found!="") print found }' "$f" | head -n1
    done
    if [ -f /etc/apt/sources.list ]; then
        awk -v c="$codename" '$1=="deb" && $3==c { print $2; exit }' /etc/apt/sources.list
    fi
}

if [ ! -f "$backports_list" ]; then
    uri="$(debian_uri | head -n1)"
    if [ -z "$uri" ]; then
        echo "setup: no Debian '$codename' source entry found in /etc/apt to derive backports from" >&2
        exit 1
    fi
    echo "setup: enabling $codename-backports from $uri"
    $SUDO tee "$backports_list" >/dev/null <<SRC
Types: deb
URIs: $uri
Suites: $codename-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
fi

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends \
    -t "$codename-backports" mesa-vulkan-drivers >/dev/null
$SUDO apt-get install -y -qq --no-install-recommends \
    libvulkan1 libvulkan-dev vulkan-validationlayers vulkan-tools \
    libshaderc-dev glslang-dev spirv-tools pkg-config g++ xvfb xauth >/dev/null

# Lavapipe must advertise mesh shaders (Mesa >= 25 from backports).
if command -v vulkaninfo >/dev/null; then
    info="$(vulkaninfo 2>/dev/null || true)"
    if ! grep -q VK_EXT_mesh_shader <<<"$info"; then
        echo "setup: warning: no Vulkan device advertises VK_EXT_mesh_shader" >&2
    fi
fi

command -v cargo >/dev/null || { echo "setup: cargo not found; install Rust (rustup)" >&2; exit 1; }
cargo fetch --quiet
echo "setup: done ($(dpkg-query -W -f='mesa-vulkan-drivers ${Version}' mesa-vulkan-drivers))"
