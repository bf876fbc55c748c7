#!/usr/bin/python3
"""The report's timings against the benchmark binary's, on one machine in one run.

Runs `mechbench sweep fourbar_free` (each rung in its own worker process, one-time costs paid
first, phases from Result::cpu) and then the Google Benchmark binary's accuracy/*/fourbar_free
benchmarks (the whole Method::Run per iteration, many iterations in one process), and prints, for
every (method, rung) both measure, the median CPU of a whole run and of its integration phase from
each, with their ratio, as a Markdown table. Usage (from the project root, after a build):

    scripts/timing_crosscheck.py [--repeats 5]
"""
import argparse
import json
import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MECHBENCH = os.path.join(ROOT, "build", "harness", "mechbench")
BENCH = os.path.join(ROOT, "build", "bench", "mechbench_bench")


def rung_key(method, control, value):
    return (method, control, float("%.6g" % value) if value is not None else None)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    for exe in (MECHBENCH, BENCH):
        if not os.access(exe, os.X_OK):
            sys.exit(f"{exe} not built: scripts/bench.sh builds both")

    sweep = json.loads(subprocess.run(
        [MECHBENCH, "sweep", "fourbar_free", "--json", "--jobs", "1", "--repeats", str(args.repeats)],
        check=True, capture_output=True, text=True).stdout)
    report = {}
    defaults = {m["method"]: m["default"] for m in sweep["methods"]}
    controls = {m["method"]: m["control"] for m in sweep["methods"]}
    for r in sweep["records"]:
        if r["kind"] != "sweep" or r["status"] != "ok" or not isinstance(r.get("cpu"), dict):
            continue
        report[rung_key(r["method"], r["control"], r["value"])] = (r["cpu_seconds"], r["cpu"]["integration"])

    out = subprocess.run(
        [BENCH, "--benchmark_filter=^accuracy/.*/fourbar_free$", "--benchmark_format=json",
         f"--benchmark_repetitions={args.repeats}", "--benchmark_report_aggregates_only=true"],
        check=True, capture_output=True, text=True).stdout
    bench = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") != "median" or "error_occurred" in b:
            continue
        name = b["run_name"]  # accuracy/<method>[/step:h | /tol:t]/fourbar_free
        parts = name.split("/")
        method, setting = parts[1], parts[2] if len(parts) == 4 else None
        if setting is None:
            value = defaults.get(method)
        else:
            value = float(re.sub(r"^(step|tol):", "", setting))
        scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}[b["time_unit"]]
        bench[rung_key(method, controls.get(method), value)] = (b["cpu_time"] * scale, b["integration_s"])

    machine = sweep["machine"]
    print(f"machine: {machine['cpu']}, {machine['cores']} cores; build {sweep['build']['build_type']}; "
          f"median of {args.repeats}")
    print()
    print("| method | rung | report: whole run | benchmark: whole run | ratio | report: integration | "
          "benchmark: integration | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for key in sorted(set(report) & set(bench), key=lambda k: (k[0], -(k[2] or 0))):
        (rw, ri), (bw, bi) = report[key], bench[key]
        rung = ("h = %g s" if key[1] == "step" else "tol %g") % key[2]
        print(f"| {key[0]} | {rung} | {rw * 1e3:.3g} ms | {bw * 1e3:.3g} ms | {rw / bw:.2f} | "
              f"{ri * 1e3:.3g} ms | {bi * 1e3:.3g} ms | {ri / bi:.2f} |")
        worst = max(worst, abs(ri / bi - 1))
    print()
    print(f"largest integration difference: {worst * 100:.0f} %")


if __name__ == "__main__":
    main()
