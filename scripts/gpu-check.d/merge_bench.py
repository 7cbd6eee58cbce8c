#!/usr/bin/env python3
"""Joins Google Benchmark JSON reports into one: the first report's context
(with every program's own context under "contexts"), and every benchmark with
the name of the program that ran it ("executable").

    scripts/gpu-check.d/merge_bench.py OUT.json REPORT.json...
"""
import json
import os
import sys


def main():
    if len(sys.argv) < 3:
        print(__doc__.strip().splitlines()[-1].strip(), file=sys.stderr)
        return 2
    merged = {"context": None, "contexts": {}, "benchmarks": []}
    for path in sys.argv[2:]:
        name = os.path.splitext(os.path.basename(path))[0]
        try:
            with open(path) as f:
                report = json.load(f)
        except (OSError, ValueError) as e:
            print(f"{path}: {e}", file=sys.stderr)
            continue
        ctx = report.get("context", {})
        merged["contexts"][name] = ctx
        if merged["context"] is None:
            merged["context"] = dict(ctx)
        for b in report.get("benchmarks", []):
            merged["benchmarks"].append(dict(b, executable=name))
    if merged["context"] is None:
        print("no report could be read", file=sys.stderr)
        return 1
    merged["context"]["executables"] = sorted(merged["contexts"])
    with open(sys.argv[1], "w") as f:
        json.dump(merged, f, indent=2)
        f.write("\n")
    print(f"{len(merged['benchmarks'])} benchmarks from {len(merged['contexts'])} programs -> {sys.argv[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
