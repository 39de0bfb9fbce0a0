#!/usr/bin/env bash
# Vulkan on a headless NVIDIA machine without package access, and the GPU
# benchmark (`tet-bench gpu-bench`) as one prepared command.
#
# A GPU machine of this kind often has the NVIDIA driver but no Vulkan
# loader (libvulkan.so.1) and no package access; the loader (and, for GL
# and EGL programs, glvnd's libraries) then travel with the benchmark as
# .deb files, unpacked there with `dpkg -x`.
#
#   scripts/gpu/headless-nvidia.sh download [DEB_DIR]
#       On a Debian/Ubuntu machine with package access (any processor):
#       fetch the amd64 packages libvulkan1 libegl1 libglvnd0 libopengl0
#       libgl1 libglx0 libgles2 into DEB_DIR (default .gl, about 1 MB).
#   scripts/gpu/headless-nvidia.sh prepare MESH_DIR [gpu-bench flags]
#       On the CPU side: build the scenes' meshes into MESH_DIR and check
#       them against what is left of 60 MB once the binary and DEB_DIR
#       are counted (meshes.json lands in MESH_DIR/report/).
#   scripts/gpu/headless-nvidia.sh check
#       On the GPU machine: set the loader up, print the adapter wgpu finds
#       (name, backend, device type, driver); fail on a software adapter.
#   scripts/gpu/headless-nvidia.sh bench OUT_DIR [gpu-bench flags]
#       check, then `tet-bench gpu-bench OUT_DIR [flags]`: gpu.json and
#       gpu.md in OUT_DIR (docs/cli.md, docs/json.md), and, where
#       nvidia-smi is there, the clocks before and after in
#       OUT_DIR/nvidia-smi.csv.
#
# Environment: TET_BENCH, the binary (default target/release/tet-bench,
# built with `cargo build --release -p tet-bench --features gpu`); DEB_DIR
# (default .gl); ALLOW_SOFTWARE=1 lets `check` and `bench` accept a
# software adapter (to try the script on lavapipe).
#
# The whole flow:
#   cargo build --release -p tet-bench --features gpu
#   scripts/gpu/headless-nvidia.sh download .gl
#   scripts/gpu/headless-nvidia.sh prepare .meshes
#   # carry target/release/tet-bench, .gl and .meshes to the GPU machine; there:
#   scripts/gpu/headless-nvidia.sh bench gpu-results --meshes .meshes
set -euo pipefail

TET_BENCH="${TET_BENCH:-target/release/tet-bench}"
DEB_DIR="${DEB_DIR:-.gl}"
PACKAGES=(libvulkan1 libegl1 libglvnd0 libopengl0 libgl1 libglx0 libgles2)
NVIDIA=/usr/local/nvidia
CARRY_LIMIT_MB=60

die() {
    echo "error: $*" >&2
    exit 1
}

# The amd64 packages, fetched with apt-get's own lists for amd64 (so that
# it works on a machine of another processor too).
download() {
    local dir="${1:-$DEB_DIR}"
    local lists=/tmp/amd64-lists
    mkdir -p "$dir" "$lists/partial"
    local o=(-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 "-oDir::State::Lists=$lists")
    apt-get "${o[@]}" update
    (cd "$dir" && apt-get "${o[@]}" download "${PACKAGES[@]}")
    ls -l "$dir"
}

# Bytes of a file or folder (0 when missing).
bytes_of() {
    if [ -e "$1" ]; then du -sb "$1" | cut -f1; else echo 0; fi
}

prepare() {
    local meshes="${1:?usage: $0 prepare MESH_DIR [gpu-bench flags]}"
    shift
    [ -x "$TET_BENCH" ] || die "no $TET_BENCH: cargo build --release -p tet-bench --features gpu"
    local binary debs left
    binary="$(bytes_of "$TET_BENCH")"
    debs="$(bytes_of "$DEB_DIR")"
    left="$(awk -v b="$binary" -v d="$debs" -v l="$CARRY_LIMIT_MB" 'BEGIN { x = l - (b + d) / 1e6; print (x > 0 ? x : 0) }')"
    echo "binary $((binary / 1000000)) MB, packages $((debs / 1000000)) MB: ${left} MB left for the meshes"
    "$TET_BENCH" gpu-bench "$meshes/report" --prepare-meshes --meshes "$meshes" --budget-mb "$left" "$@"
}

# The Vulkan loader, unpacked from DEB_DIR where the system has none, and
# the NVIDIA driver's ICD where the loader would not find it.
setup() {
    if ! ldconfig -p | grep -q libvulkan; then
        shopt -s nullglob
        local debs=("$DEB_DIR"/*.deb)
        shopt -u nullglob
        [ "${#debs[@]}" -gt 0 ] ||
            die "no Vulkan loader (libvulkan.so.1) and no .deb files in $DEB_DIR: run '$0 download $DEB_DIR' where packages can be fetched, and carry $DEB_DIR here"
        for f in "${debs[@]}"; do
            dpkg -x "$f" /
        done
        ldconfig
        ldconfig -p | grep -q libvulkan || die "libvulkan.so.1 is still missing after unpacking ${debs[*]}"
        echo "unpacked ${#debs[@]} packages from $DEB_DIR"
    fi
    local icd
    icd="$(ls /usr/share/vulkan/icd.d/nvidia_icd*.json /etc/vulkan/icd.d/nvidia_icd*.json 2>/dev/null || true)"
    if [ -z "$icd" ] && [ -z "${VK_DRIVER_FILES:-}${VK_ICD_FILENAMES:-}" ]; then
        if [ -f "$NVIDIA/share/vulkan/icd.d/nvidia_icd.json" ]; then
            export VK_DRIVER_FILES="$NVIDIA/share/vulkan/icd.d/nvidia_icd.json"
            export __EGL_VENDOR_LIBRARY_FILENAMES="$NVIDIA/share/glvnd/egl_vendor.d/10_nvidia.json"
            echo "NVIDIA driver: VK_DRIVER_FILES=$VK_DRIVER_FILES"
            if [ -d "$NVIDIA/lib64" ] && ! ldconfig -p | grep -q libGLX_nvidia; then
                export LD_LIBRARY_PATH="$NVIDIA/lib64${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
            fi
        else
            echo "warning: no NVIDIA Vulkan driver file (nvidia_icd.json) found" >&2
        fi
    fi
    # Mesa's and the loader's window-system probes ask for a runtime dir.
    if [ -z "${XDG_RUNTIME_DIR:-}" ]; then
        XDG_RUNTIME_DIR="$(mktemp -d)"
        export XDG_RUNTIME_DIR
    fi
}

# The GPU's clocks, power and temperature as nvidia-smi reads them (when
# the machine has it), one line per call, into OUT_DIR/nvidia-smi.csv:
# wgpu does not report clocks.
clocks() {
    command -v nvidia-smi >/dev/null || return 0
    local f="$out/nvidia-smi.csv"
    local q=name,driver_version,clocks.sm,clocks.max.sm,clocks.mem,power.draw,temperature.gpu
    [ -f "$f" ] || echo "when,$q" >"$f"
    nvidia-smi --query-gpu="$q" --format=csv,noheader | sed "s/^/$1,/" >>"$f" || true
}

check() {
    [ -x "$TET_BENCH" ] || die "no $TET_BENCH (set TET_BENCH, or build it: cargo build --release -p tet-bench --features gpu)"
    local allow=()
    [ "${ALLOW_SOFTWARE:-0}" = 1 ] && allow=(--allow-software)
    # gpu-bench --adapter-only prints the adapter and fails on software.
    "$TET_BENCH" gpu-bench "${TMPDIR:-/tmp}" --adapter-only "${allow[@]}"
}

case "${1:-}" in
download)
    shift
    download "$@"
    ;;
prepare)
    shift
    prepare "$@"
    ;;
check)
    setup
    check
    ;;
bench)
    shift
    out="${1:?usage: $0 bench OUT_DIR [gpu-bench flags]}"
    shift
    setup
    check
    mkdir -p "$out"
    clocks before
    "$TET_BENCH" gpu-bench "$out" "$@"
    clocks after
    ;;
*)
    sed -n '2,37p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
