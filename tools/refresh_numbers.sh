#!/bin/bash
# Refresh every measured number of README.md and docs/*.md from new runs (docs/numbers.md).
#
#   tools/refresh_numbers.sh            # the full-size runs the pages describe (about an hour on 2 cores)
#   tools/refresh_numbers.sh --quick    # short spans: checks the pipeline; the pages then show those spans
#
# Run it on a quiet machine: the speed numbers record the machine, its load and the date.  Each step
# updates its own JSON record under docs/data/ (bench models and test numbers are merged: the entries
# of what ran are replaced, the others kept), then the pages are rendered and checked.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=docs/data
WORK=$(mktemp -d "${TMPDIR:-/tmp}/tqdyn-refresh.XXXXXX")
trap 'rm -rf "$WORK"' EXIT
QUICK=0
[ "${1:-}" = "--quick" ] && QUICK=1
mkdir -p "$DATA"

# 1. benchmarks (tqdyn bench --json): one entry per model
if [ $QUICK = 1 ]; then
    tqdyn bench --model kepler --model lisa --model lisa-coupled --model kernels --model default-run \
        --model startup --model lisa-10y --json "$DATA/bench.json"
    tqdyn bench --model full --model coupled --duration 2d --json "$DATA/bench.json"
    tqdyn bench --model tianqin-5y --model tianqin-5y-multistep --duration 10d --json "$DATA/bench.json"
    tqdyn bench --model closed-loop --duration 6h --json "$DATA/bench.json"
else
    tqdyn bench --model all --model default-run --model startup --model tianqin-5y --model tianqin-5y-multistep \
        --model lisa-10y --model closed-loop --json "$DATA/bench.json"
fi

# 2. the paper's studies on TianQin and on LISA (summary.json of tqdyn report --studies), in fresh
#    run folders so that every run's wall time is measured
SCALE=()
[ $QUICK = 1 ] && SCALE=(--quick)
tqdyn report --studies "${SCALE[@]}" --out "$WORK/studies-tianqin" -q > "$WORK/studies-tianqin.log"
cp "$WORK/studies-tianqin/summary.json" "$DATA/studies-tianqin.json"
tqdyn report --studies --mission lisa "${SCALE[@]}" --out "$WORK/studies-lisa" -q > "$WORK/studies-lisa.log"
cp "$WORK/studies-lisa/summary.json" "$DATA/studies-lisa.json"
# the closed loop's default designs at the working points of short coupled runs (figures: docs/figures/closed-loop-*)
tqdyn report --closed-loop --out "$WORK/closed-loop" -q > "$WORK/closed-loop.log"
cp "$WORK/closed-loop/summary.json" "$DATA/closed-loop.json"
for f in tianqin-tm-acceleration lisa-tm-acceleration taiji-tm-acceleration tianqin-budget tianqin-loops; do
    cp "$WORK/closed-loop/closed-loop/$f.png" "docs/figures/closed-loop-$f.png"
done

# the covariance study of orbit determination (docs/orbit-determination.md; about a minute)
if [ $QUICK = 1 ]; then
    python tools/od_study.py --quick --out "$DATA/od-study.json" --figure docs/figures/od-study.png
else
    python tools/od_study.py --out "$DATA/od-study.json" --figure docs/figures/od-study.png
fi
# its worked example with the residuals' figure (about a minute)
python tools/od_residuals.py --out "$DATA/od-residuals.json" --figure docs/figures/od-residuals.png

# 3. the pages from the new benchmark and study records (so that the suite's page checks pass)
python tools/render_docs.py

# 4. the numbers the tests measure (record_number): the default suite (its duration and each file's too),
#    then the slow tests that record numbers
python -m pytest -p no:cacheprovider -q --record-numbers "$DATA/tests.json" tests
python -m pytest -p no:cacheprovider -q --record-numbers "$DATA/tests.json" --numbers-only -m slow tests

# 5. the pages again, from the new test records, and the check
python tools/render_docs.py
python tools/render_docs.py --check
