"""Kepler benchmark: 3 TianQin satellites, Earth monopole, 90 days at 50 s,
tqdyn dd vs float64 vs heyoka real128 (if installed).  Same as `tqdyn bench`.

Usage: python benchmarks/bench_kepler.py [--duration 90d] [--step 50] [--json out.json]
"""

from __future__ import annotations

import argparse
import json

from tqdyn.workflows.bench import format_report, kepler_benchmark


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", default="90d")
    ap.add_argument("--step", default="50")
    ap.add_argument("--no-heyoka", action="store_true")
    ap.add_argument("--json", help="also write the raw numbers to this file")
    args = ap.parse_args()
    report = kepler_benchmark(duration=args.duration, step=args.step, heyoka=not args.no_heyoka)
    print(format_report(report))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(report, fh, indent=2)


if __name__ == "__main__":
    main()
