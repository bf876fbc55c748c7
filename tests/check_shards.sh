#!/usr/bin/env bash
# check_shards.sh MECHBENCH OUT_DIR [mechbench report arguments…]
#
# The same report three ways: one run; two shards run at once with GNU parallel (or one after
# the other when parallel is missing) and merged with `mechbench merge`. The merged
# results.json must hold the same records as the single run — same cases, statuses, outcomes,
# errors and settings — with only the timings (CPU, wall, creation time) allowed to differ.
# Exit 0 same, 1 different or failed, 2 bad usage.
set -euo pipefail
if [[ $# -lt 2 ]]; then
  echo "usage: $0 MECHBENCH OUT_DIR [report arguments…]" >&2
  exit 2
fi
exe=$1
out=$2
shift 2
rm -rf "$out"
mkdir -p "$out"
"$exe" report "$@" --jobs 2 --out "$out/whole" >"$out/whole.log" 2>&1 || [[ $? -eq 1 ]]
if command -v parallel >/dev/null 2>&1; then
  echo "shards with GNU parallel"
  parallel --will-cite --halt now,fail=1 "$exe" report "$@" --shard {}/2 --out "$out/shards" ::: 1 2 >"$out/shards.log" 2>&1
else
  echo "GNU parallel not installed: shards one after the other"
  for k in 1 2; do "$exe" report "$@" --shard "$k/2" --out "$out/shards" >>"$out/shards.log" 2>&1; done
fi
"$exe" merge "$out"/shards/shard-*-of-2.jsonl --out "$out/merged" >"$out/merge.log" 2>&1 || [[ $? -eq 1 ]]
/usr/bin/python3 - "$out/whole/results.json" "$out/merged/results.json" <<'PY'
import json, sys
TIMING = {"cpu_seconds", "cpu_min", "cpu_max", "cpu", "startup", "wall_seconds"}

def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in TIMING}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x

a, b = (json.load(open(p)) for p in sys.argv[1:3])
ra, rb = strip(a["records"]), strip(b["records"])
if len(ra) != len(rb):
    sys.exit(f"FAIL: {len(ra)} records in one run, {len(rb)} merged from shards")
bad = [(x["id"], y["id"]) for x, y in zip(ra, rb) if x != y]
for x, y in zip(ra, rb):
    if x != y:
        diff = {k: (x.get(k), y.get(k)) for k in set(x) | set(y) if x.get(k) != y.get(k)}
        print("differs:", x["id"], json.dumps(diff)[:400])
        break
if bad:
    sys.exit(f"FAIL: {len(bad)} of {len(ra)} records differ")
for key in ("scenarios", "methods", "derived"):
    da = strip(a[key]) if key != "derived" else [{k: v for k, v in d.items() if not k.startswith(("cpu_to", "setup_at"))} for d in a[key]]
    db = strip(b[key]) if key != "derived" else [{k: v for k, v in d.items() if not k.startswith(("cpu_to", "setup_at"))} for d in b[key]]
    if da != db:
        sys.exit(f"FAIL: '{key}' differs between one run and the merged shards")
print(f"ok: {len(ra)} records, one run and two merged shards agree (timings aside)")
PY
