#!/usr/bin/env bash
# Run every built-in scenario (and a few variants) with the installed tqdyn
# into OUTDIR, so that two versions of the code can be compared field by field
# with tools/compare_trajectories.py (the restructuring of version 0.2 was
# checked this way: every file bit-identical).
#   usage: tools/builtin_outputs.sh OUTDIR [DURATION]
set -euo pipefail
out=${1:?usage: builtin_outputs.sh OUTDIR [DURATION]}
dur=${2:-2d}
mkdir -p "$out"
cd "$out"   # relative output names: the resolved scenario (in each file) names its output
for s in $(python -c "from tqdyn.scenario import builtin_scenarios as b; print(' '.join(b()))" 2>/dev/null \
           || python -c "import tqdyn; print(' '.join(tqdyn.builtin_scenarios()))"); do
    tqdyn run "$s" --duration "$dur" --quiet --output "$s.h5" --checkpoint-every 0 >/dev/null
done
tqdyn run --quiet --output "default.h5" >/dev/null
tqdyn run --duration "$dur" --quiet --precision float64 --output "tianqin-float64.h5" >/dev/null
tqdyn run --duration 1d --quiet --set constellation.free_tms=true --output "tianqin-free.h5" >/dev/null
tqdyn run --duration 1d --quiet --set constellation.pointing=iterative --set constellation.free_tms=true \
    --output "tianqin-iterative-free.h5" >/dev/null
tqdyn run tianqin-dragfree-local --duration 6h --quiet --set integrator.mode=adaptive --set integrator.rtol=1e-18 \
    --output "tianqin-adaptive.h5" >/dev/null
tqdyn export "default.h5" --format lisa "default-lisa.h5" >/dev/null
