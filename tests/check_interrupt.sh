#!/usr/bin/env bash
# Ctrl-C (SIGINT) during `run` and `report`: one line on stderr saying the command was interrupted
# and what was (not) written (run's results "partial" only when a table was printed), exit code 130, the outputs as they were (no truncated file, no
# temporary left beside them). Usage: check_interrupt.sh MECHBENCH DATA_DIR WORK_DIR
set -u
set -m  # background jobs in their own process group: SIGINT is not ignored in them
exe=$1 data=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fail=0
# Starts the command, waits until it has worked for $1 s, sends SIGINT, and sets rc and err.
interrupt() {
  local after=$1
  shift
  "$exe" "$@" >stdout.txt 2>stderr.txt &
  local pid=$!
  sleep "$after"
  if ! kill -0 "$pid" 2>/dev/null; then
    wait "$pid"
    echo "FAIL: mechbench $* ended (exit $?) before the interrupt at $after s"
    fail=1
    rc=-1 err=$(cat stderr.txt)
    return
  fi
  kill -INT "$pid"
  wait "$pid"
  rc=$?
  err=$(cat stderr.txt)
}
check() {  # what, expected stderr text
  if [[ $rc -ne 130 || "$err" != *"$2"* ]]; then
    echo "FAIL: $1: exit $rc (expected 130), stderr lacks '$2':"
    echo "$err" | tail -5
    fail=1
  else
    echo "ok: $1: exit 130: $(grep 'interrupted' <<<"$err")"
  fi
  if [ "$(grep -c 'interrupted (SIGINT)' <<<"$err")" != 1 ]; then
    echo "FAIL: $1: not one 'interrupted' line"
    fail=1
  fi
}

# run: a long free scene through several methods; an existing --csv file stays as it was.
echo "old contents" >old.csv
interrupt 2 run "$data/scenes/fourbar_free_long.yaml" --method numeric --method dyn-baumgarte-rk4 \
  --method dyn-ali3p --method dyn-coordinate-partitioning --csv old.csv --budget 0
check "run --csv" "mechbench run: interrupted (SIGINT); nothing was printed yet and nothing written (--csv old.csv left as it was)"
[ "$(cat old.csv)" = "old contents" ] || { echo "FAIL: old.csv changed"; fail=1; }
if ls -A | grep -q partial; then echo "FAIL: a temporary file was left: $(ls -A)"; fail=1; fi
[ -s stdout.txt ] && { echo "FAIL: run printed before the interrupt, so the test no longer tells the two notes apart"; fail=1; }
# A quick scene's table printed (and flushed) before the long one: now the printed results are partial.
interrupt 3 run "$data/scenes/spring_bob_damper_only.yaml" "$data/scenes/fourbar_free_long.yaml" --method numeric \
  --method dyn-baumgarte-rk4 --method dyn-ali3p --method dyn-coordinate-partitioning --budget 0
check "run, a scene printed" "mechbench run: interrupted (SIGINT); the results printed so far are partial; nothing written (no file was asked for)"
grep -q 'spring_bob_damper_only' stdout.txt || { echo "FAIL: the first scene's table is not in stdout"; fail=1; }

# report: interrupted while its cases run; the folder holds no report file and no temporary.
interrupt 3 report --quick --jobs 1 --out rep "$data/scenes/fourbar_free_long.yaml" --method numeric --method dyn-ali3p \
  --method dyn-baumgarte-rk4 --method dyn-coordinate-partitioning
check "report" "mechbench report: interrupted (SIGINT); nothing written (the report in rep is as it was)"
left=$(ls -A rep 2>/dev/null | grep -v '^.mechbench-report.lock$')
[ -z "$left" ] || { echo "FAIL: report folder holds: $left"; fail=1; }
[ $fail = 0 ] && echo ok
exit $fail
