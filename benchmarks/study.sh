#!/bin/bash
# A shipped case at a study-size mesh, 31 speeds 0..30,000 r/min, the whole
# chain (static contact + damped eigenvalues, 12 modes, stress stiffening on)
# or the static sweep alone: DOFs, peak memory, time per phase, factorisations.
# Usage (from the repository root, after building into build/):
#   bash benchmarks/study.sh CASE [h_fit] [h_max]     CASE = test_shaft | conical_impeller
#   STATIC_ONLY=1 bash benchmarks/study.sh ...        static sweep only (Compute modes = false)
#   SPEEDS="0, 15000, 30000" bash benchmarks/study.sh ...   a speed list instead of 0..30,000
#   ROTORFIT=path overrides build/rotorfit
# Results: benchmarks/output/<CASE>_<h_fit>_<h_max>[_static]/{log.txt,summary.txt,time.txt,...}
set -euo pipefail
cd "$(dirname "$0")/.."
case=${1:?CASE = test_shaft or conical_impeller}
h_fit=${2:-2.5e-3}
h_max=${3:-5e-3}
out=benchmarks/output/${case}_${h_fit}_${h_max}${STATIC_ONLY:+_static}${SPEEDS:+_list}
modes=true
[ -n "${STATIC_ONLY:-}" ] && modes=false
mkdir -p "$out"
sed -e "s|^\( *set Geometry parameters *=\).*|\1 h_fit: ${h_fit}, h_max: ${h_max}|" \
    -e "s|^\( *set Directory *=\).*|\1 ${out}|" \
    -e "s|^\( *set Write ParaView files *=\).*|\1 false|" \
    -e "s|^\( *set Geometry file *=\).*|\1 $(pwd)/prm/${case}.geo|" \
    prm/${case}.prm > "$out/case.prm"
if [ -n "${SPEEDS:-}" ]; then
  cat >> "$out/case.prm" <<PRM
subsection Speeds
  set Mode = list
  set List = ${SPEEDS}
end
PRM
fi
cat >> "$out/case.prm" <<PRM
subsection Eigenproblem
  set Compute modes     = ${modes}
  set Write mode shapes = false
end
PRM
/usr/bin/time -v "${ROTORFIT:-./build/rotorfit}" "$out/case.prm" 2> "$out/time.txt" | tail -25
grep -E "Maximum resident|Elapsed" "$out/time.txt"
