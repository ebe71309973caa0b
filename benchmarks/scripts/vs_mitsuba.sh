#!/usr/bin/env bash
# Times `sfp render` and Mitsuba 3 (llvm_ad_mono_polarized) on the same scene,
# whole process each (start-up, scene loading, rendering, writing files),
# alternating, back to back in one run:
#   benchmarks/scripts/vs_mitsuba.sh [RUNS]        (default 3)
# The scene is vs_mitsuba_sphere.toml / vs_mitsuba_sphere.py: 512²
# orthographic sphere, 64 spp, max_depth 4, one directional light, specular
# off. Prints every run, the medians, their ratio and sfp's rays/s.
#
# Mitsuba is used for this comparison only: it is installed from PyPI
# (`mitsuba`) into a virtual environment on first use (MITSUBA_VENV, default
# ~/.cache/sfp-mitsuba-venv). Its LLVM backend needs the shared libLLVM of
# LLVM 16 or newer (Debian: apt-get install libllvm19); the newest one found
# is used unless DRJIT_LIBLLVM_PATH is set. SFP selects the sfp binary
# (default: built here with `cargo build --release --bin sfp`).
# Not part of CI: it needs the network once and takes a minute.
set -euo pipefail

runs=${1:-3}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
venv=${MITSUBA_VENV:-$HOME/.cache/sfp-mitsuba-venv}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

if [ -z "${SFP:-}" ]; then
    (cd "$root" && cargo build --release --bin sfp)
    SFP=${CARGO_TARGET_DIR:-$root/target}/release/sfp
fi

if ! "$venv/bin/python" -c 'import mitsuba' 2>/dev/null; then
    echo "installing mitsuba into $venv" >&2
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet mitsuba
fi
if [ -z "${DRJIT_LIBLLVM_PATH:-}" ]; then
    llvm=$(ls /usr/lib/*/libLLVM-[0-9]*.so /usr/lib/llvm-*/lib/libLLVM*.so 2>/dev/null |
        sed -n 's/.*libLLVM-\([0-9][0-9]*\)\.so$/\1 &/p' | sort -n | tail -1)
    if [ -z "$llvm" ] || [ "${llvm%% *}" -lt 16 ]; then
        echo "Mitsuba's LLVM backend needs libLLVM >= 16 (found: ${llvm:-none});" \
            "install one (Debian: apt-get install libllvm19) or set DRJIT_LIBLLVM_PATH" >&2
        exit 1
    fi
    export DRJIT_LIBLLVM_PATH=${llvm#* }
fi

# Wall and CPU seconds of one command: "wall user+sys".
timed() {
    local log=$1
    shift
    local start end
    start=$(date +%s.%N)
    "$@" >"$log" 2>&1
    end=$(date +%s.%N)
    echo "$start $end" | awk '{printf "%.2f", $2 - $1}'
}

sfp_run() { "$SFP" render "$here/vs_mitsuba_sphere.toml" --out "$work/sfp"; }
mitsuba_run() { "$venv/bin/python" "$here/vs_mitsuba_sphere.py" "$work/mitsuba.exr"; }

# Warm-up, not counted: Mitsuba compiles its kernels into a cache on the
# first run; both read their files into the page cache.
timed "$work/log" sfp_run >/dev/null
timed "$work/log" mitsuba_run >/dev/null

sfp_times=()
mitsuba_times=()
for i in $(seq "$runs"); do
    s=$(timed "$work/sfp.log" sfp_run)
    m=$(timed "$work/mitsuba.log" mitsuba_run)
    sfp_times+=("$s")
    mitsuba_times+=("$m")
    echo "run $i: sfp ${s} s, mitsuba ${m} s"
done

median() { printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
s=$(median "${sfp_times[@]}")
m=$(median "${mitsuba_times[@]}")
echo "median of $runs: sfp ${s} s, mitsuba ${m} s, ratio sfp/mitsuba $(awk -v a="$s" -v b="$m" 'BEGIN {printf "%.2f", a / b}')"
echo "sfp (last run): $(grep -o '[0-9.]* M rays/s' "$work/sfp.log")"
