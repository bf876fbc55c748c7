#!/usr/bin/env bash
# `mechbench merge` on shard files that are not one campaign's, whole: each must exit 2 with the
# file (and line) and a message, never abort, never merge. Usage: check_merge_input.sh MECHBENCH DIR
set -u
exe=$1
dir=$2
rm -rf "$dir" && mkdir -p "$dir" && cd "$dir" || exit 1
header() {  # shard shards records campaign
  printf '{"mechbench_shard":{"shard":%s,"shards":%s,"cases":%s,"records":%s,"total_cases":2,"campaign":"%s","options":{"quick":true,"repeats":1,"timeout":60,"jobs":1,"scenarios":[],"methods":[]}}}\n' "$1" "$2" "$3" "$3" "$4"
}
record() {  # index
  printf '{"id":"check/s%s","index":%s,"kind":"check","scenario":"s%s","file":"","rows":[]}\n' "$1" "$1" "$1"
}
{ header 1 2 1 aaaa; record 0; } >good-1.jsonl
{ header 2 2 1 aaaa; record 1; } >good-2.jsonl
{ header 2 2 1 bbbb; record 1; } >other-2.jsonl
{ header 1 2 1 aaaa; echo 'garbage'; } >not-json.jsonl
{ header 1 2 1 aaaa; echo '42'; } >scalar.jsonl
{ header 1 2 1 aaaa; echo '"a string"'; } >string.jsonl
{ header 1 2 1 aaaa; echo '{"kind":"check","scenario":"s0","index":0}'; } >no-id.jsonl
{ record 0; } >no-header.jsonl
{ header 1 2 2 aaaa; record 0; } >cut-short.jsonl
: >empty.jsonl
fails=0
expect() {  # message, files...
  local want=$1
  shift
  out=$("$exe" merge "$@" --out merged 2>&1)
  rc=$?
  if [[ $rc -ne 2 || "$out" != *"$want"* || "$out" != *".jsonl"* ]]; then
    echo "FAIL: merge $* -> exit $rc, expected 2 and '$want' with the file:"
    echo "$out"
    fails=$((fails + 1))
  else
    echo "ok: $* -> $out"
  fi
}
expect "not a JSON line" not-json.jsonl good-2.jsonl
expect "not a record" scalar.jsonl good-2.jsonl
expect "not a record" string.jsonl good-2.jsonl
expect "not a case record" no-id.jsonl good-2.jsonl
expect "not a shard header" no-header.jsonl good-2.jsonl
expect "cut short" cut-short.jsonl good-2.jsonl
expect "no shard header" empty.jsonl good-2.jsonl
expect "another campaign" good-1.jsonl other-2.jsonl
expect "missing" good-1.jsonl
expect "given twice" good-1.jsonl good-1.jsonl good-2.jsonl
[[ -e merged/report.html ]] && { echo "FAIL: a refused merge wrote a report"; fails=$((fails + 1)); }
# And the good pair merges.
if ! "$exe" merge good-1.jsonl good-2.jsonl --out merged >merge.log 2>&1 || [[ ! -s merged/results.json ]]; then
  echo "FAIL: the good shards did not merge:"; cat merge.log; fails=$((fails + 1))
fi
exit $((fails > 0))
