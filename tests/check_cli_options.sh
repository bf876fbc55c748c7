#!/usr/bin/env bash
# The command line on bad options and outputs: exit 2 with a message, before any work, and no
# output file touched. Usage: check_cli_options.sh MECHBENCH SOURCE_DIR WORK_DIR
set -u
exe=$1
src=$2
work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
fails=0
expect() {  # exit code, message, args...
  local code=$1 want=$2
  shift 2
  out=$("$exe" "$@" 2>&1)
  rc=$?
  if [[ $rc -ne $code || "$out" != *"$want"* ]]; then
    echo "FAIL: mechbench $* -> exit $rc, expected $code and '$want':"
    echo "$out" | head -5
    fails=$((fails + 1))
  else
    echo "ok: mechbench $* -> exit $rc"
  fi
}
expect 2 "unknown command 'frobnicate' (fix: use one of list, check, run" frobnicate
expect 2 "unknown command 'lst' (fix: did you mean 'list'? The commands are list, check" lst
expect 2 "no command given (fix: use one of list, check, run" 
expect 2 "no command given" --json
expect 2 "--timeout must be a finite number > 0" report --out r --timeout -1
expect 2 "--timeout must be a finite number > 0" report --out r --timeout 0
expect 2 "--timeout must be a finite number > 0" sweep --timeout nan
expect 2 "--budget must be a finite number ≥ 0" run --budget nan fourbar_free
expect 2 "--budget must be a finite number ≥ 0" run --budget -3 fourbar_free
expect 2 "--t1 must be a finite number > 0" generate nfourbar 2 --t1 -1
expect 2 "unknown key 'postion'" run --tolerances "$src/tests/data/tolerances/bad_unknown_key.yaml" fourbar_free
expect 2 "must be a positive number" report --out r --quick --tolerances "$src/tests/data/tolerances/bad_value.yaml"
[[ -e r ]] && { echo "FAIL: a refused report created its folder"; fails=$((fails + 1)); }
# Outputs that clash with each other or with an input (the tolerances file too), a folder for
# --tolerances (it aborted, exit 134): exit 2 before the work, the files untouched.
expect 2 "is a folder, not a tolerances file" run --tolerances "$src/tests/data" fourbar_free
cp "$src/tests/data/tolerances/user.yaml" mine.yaml
expect 2 "--junit names an input of this command" run fourbar_free --method numeric --tolerances mine.yaml --junit mine.yaml
cmp -s mine.yaml "$src/tests/data/tolerances/user.yaml" || { echo "FAIL: --junit overwrote the tolerances file"; fails=$((fails + 1)); }
expect 2 "--csv and --junit name the same file" run fourbar_free --method numeric --csv same.out --junit ./same.out
[[ -e same.out ]] && { echo "FAIL: a refused run wrote its output"; fails=$((fails + 1)); }
expect 2 "the report's results.json and --junit name the same file" report --out r2 --quick --junit r2/results.json
# --csv /dev/stdout with stdout in a file: the table and the CSV both there (the file was
# opened anew and written over), and a link to a file stays a link.
"$exe" run fourbar_free --method numeric --csv /dev/stdout >both.out 2>/dev/null
if grep -q "verdict:" both.out && grep -q "^scenario,method,sample" both.out; then
  echo "ok: --csv /dev/stdout into a file keeps the table and the CSV"
else
  echo "FAIL: --csv /dev/stdout into a file lost the table or the CSV"; fails=$((fails + 1))
fi
echo old >real.csv && ln -sf real.csv link.csv
"$exe" run fourbar_free --method numeric --csv link.csv >/dev/null 2>&1
if [[ -L link.csv ]] && grep -q "^scenario,method,sample" real.csv; then
  echo "ok: --csv through a link writes the file behind it and keeps the link"
else
  echo "FAIL: --csv through a link replaced the link"; fails=$((fails + 1))
fi

# --tolerances: a user's file judges the user's scene (its own free tolerance for RK4).
out=$("$exe" run "$src/tests/data/scenes/pendulum_horizontal.yaml" --method dyn-baumgarte-rk4 --json \
        --tolerances "$src/tests/data/tolerances/user.yaml" 2>/dev/null)
if [[ "$out" != *'"tolerance": 1e-09'* ]]; then
  echo "FAIL: run --tolerances did not take the user's free tolerance"; echo "$out" | grep -m3 tolerance
  fails=$((fails + 1))
else
  echo "ok: run --tolerances takes the user's free tolerance"
fi

# --csv: an input is never an output; a failing command leaves an existing file as it was.
cp "$src/scenarios/fourbar_crank_rocker.yaml" mine.yaml
cp mine.yaml mine.before
expect 2 "--csv names an input" run mine.yaml --csv mine.yaml --method analytic
cmp -s mine.yaml mine.before || { echo "FAIL: run --csv overwrote its own input"; fails=$((fails + 1)); }
echo "old,contents" >old.csv
expect 2 "no scenario file or built-in scenario" run nosuch --csv old.csv
[[ "$(cat old.csv)" == "old,contents" ]] || { echo "FAIL: a failed run emptied its --csv file"; fails=$((fails + 1)); }
ls ./*.partial-* >/dev/null 2>&1 && { echo "FAIL: a temporary file was left behind"; fails=$((fails + 1)); }
# A scene that loads but cannot be set up (INVALID SCENE, exit 2) writes nothing either.
expect 2 "not written: old.csv left as it was" run "$src/tests/data/bad/121_spatial_driver_out_of_reach.yaml" --csv old.csv
[[ "$(cat old.csv)" == "old,contents" ]] || { echo "FAIL: a run refused at set-up replaced its --csv file"; fails=$((fails + 1)); }
expect 0 "wrote" run mine.yaml --csv new.csv --method analytic --method numeric
[[ -s new.csv ]] || { echo "FAIL: run --csv wrote nothing"; fails=$((fails + 1)); }

# An interrupted run --csv (killed while it runs: no destructor runs) leaves neither its
# temporary file nor a truncated target. SIGTERM: a script's background job ignores SIGINT
# (tests/harness_output_test.cc interrupts with SIGINT as well).
echo "old,contents" >killed.csv
"$exe" run "$src/scenarios/benchmarks/a01_pendulum.yaml" --method dyn-baumgarte-rk4 --csv killed.csv >/dev/null 2>&1 &
pid=$!
for _ in $(seq 1 100); do ls killed.csv.partial-* >/dev/null 2>&1 && break; sleep 0.05; done
sleep 0.2
kill -TERM $pid
wait $pid
rc=$?
if [[ $rc -ne 143 ]]; then
  echo "FAIL: an interrupted run ended with $rc, not 143 (SIGTERM)"; fails=$((fails + 1))
elif ls ./killed.csv.partial-* >/dev/null 2>&1 || [[ "$(cat killed.csv)" != "old,contents" ]]; then
  echo "FAIL: an interrupted run --csv left its temporary file or changed its target"; fails=$((fails + 1))
else
  echo "ok: an interrupted run --csv leaves nothing behind"
fi

# report --out: a file in the way or an unwritable place is refused before any case runs.
touch a-file
expect 2 "is a file, not a folder" report --quick --out a-file fourbar_free --method analytic
expect 2 "cannot create the folder" report --quick --out /proc/no/such --method analytic
# list takes files as every other command does; one that does not load is still a row, and bad
# input (exit 2, its file, line and fix on stderr) as for every command.
expect 0 "odd_names" list "$src/tests/data/scenes/odd_names.yaml"
# check --help says what its exit code means: a printed value that differs is reported, not failed.
expect 0 'even where a printed value `differs`' check --help
expect 2 "21_guide_through_one_point.yaml:12: the guide of slider A runs through O and GV, which coincide" \
  list "$src/tests/data/scenes/odd_names.yaml" "$src/tests/data/bad/21_guide_through_one_point.yaml"
expect 2 "INVALID: " list "$src/tests/data/bad/21_guide_through_one_point.yaml"
# ... and its message once (on stderr), not again in the table.
n=$("$exe" list "$src/tests/data/bad/21_guide_through_one_point.yaml" 2>&1 | grep -c "which coincide")
if [ "$n" != 1 ]; then echo "FAIL: list prints a bad file's message $n times, expected once"; fails=$((fails + 1)); else echo "ok: list says a bad file's message once"; fi
# A rack's slider points (no pins) have no reaction: the method that gives reactions says why.
why=$("$exe" run "$src/tests/data/scenes/rack_pinion_free.yaml" --method dyn-baumgarte-rk4 --json 2>/dev/null)
if [[ "$why" == *"point R1: a slider's point (sliders are left out: the force of its guide on rack is not a pin's reaction)"* ]]; then
  echo "ok: a rack's slider point says why it has no reaction"
else
  echo "FAIL: run on rack_pinion_free: no reason for the slider point R1's reaction"; fails=$((fails + 1))
fi
expect 2 '"error": ' list --json "$src/tests/data/bad/21_guide_through_one_point.yaml"

# check with engines: each held to its own tolerance (an engine's finite-difference aabs is not a
# disagreement), exit 0; a method's n/a cells carry its reason; the book column holds numbers, a
# long quantity its own line instead of being cut.
if "$exe" list --json s3_1_carousel | grep -q '"bullet-rigidbody-default"' &&
   "$exe" list --json s3_1_carousel | grep -q '"ode-worldstep-tuned"'; then
  out=$("$exe" check s3_1_carousel --method analytic --method ode-worldstep-tuned --method bullet-rigidbody-default 2>&1)
  rc=$?
  if [[ $rc -ne 0 || "$out" == *"METHODS DISAGREE"* ]]; then
    echo "FAIL: check with engines on s3_1_carousel -> exit $rc"; echo "$out" | grep -m3 DISAGREE; fails=$((fails + 1))
  elif [[ "$out" != *"bullet-rigidbody-default: n/a for"*"none at t0"* ]]; then
    echo "FAIL: check's n/a cells lack their reason"; fails=$((fails + 1))
  elif [[ "$out" != *$'\n  -sqrt(3)*0.5/8 - omega.bar^2*(p.D.y - p.A.y)\n'* || "$out" == *" 3*1 "* ]]; then
    echo "FAIL: check's quantity or book column"; echo "$out" | head -6; fails=$((fails + 1))
  else
    echo "ok: check with engines: their own tolerances, n/a with reasons, numbers in the book column"
  fi
fi
# run --verbose on a free scene leaves out the settings that do not apply there.
out=$("$exe" run "$src/tests/data/scenes/pendulum_user_plain.yaml" --verbose 2>&1)
if [[ "$out" == *"setting drivers:"* || "$out" == *"setting loop_closures: 0 ×"* ]]; then
  echo "FAIL: run --verbose lists drivers or loop closures on a free pendulum"; fails=$((fails + 1))
else
  echo "ok: run --verbose lists only the settings that apply"
fi
exit $((fails > 0))
