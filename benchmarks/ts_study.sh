#!/bin/bash
# TS at the study's mesh size (2.5 mm at the fit), 31 speeds 0..30,000 r/min,
# static contact sweep: DOFs, peak memory, time per phase, factorisations.
# Usage (from the repository root, after building into build/):
#   bash benchmarks/ts_study.sh [h_fit] [h_max]   (ROTORFIT=path overrides build/rotorfit)
# Results: benchmarks/output/ts_study_<h_fit>_<h_max>/{log.txt,summary.txt,time.txt}
set -euo pipefail
cd "$(dirname "$0")/.."
h_fit=${1:-2.5e-3}
h_max=${2:-3e-3}
out=benchmarks/output/ts_study_${h_fit}_${h_max}
mkdir -p "$out"
sed -e "s|  set Geometry parameters = .*|  set Geometry parameters = h_fit: ${h_fit}, h_max: ${h_max}|" \
    -e "s|  set Directory            = output/test_shaft|  set Directory            = ${out}|" \
    -e "s|  set Write ParaView files = true|  set Write ParaView files = false|" \
    -e "s|  set Geometry file       = test_shaft.geo|  set Geometry file       = $(pwd)/prm/test_shaft.geo|" \
    prm/test_shaft.prm > "$out/case.prm"
/usr/bin/time -v "${ROTORFIT:-./build/rotorfit}" "$out/case.prm" 2> "$out/time.txt" | tail -25
grep -E "Maximum resident|Elapsed" "$out/time.txt"
