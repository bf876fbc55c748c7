#!/usr/bin/env bash
# The CI gate (README "Gating a CI job on mechbench", harness/include/mechbench/harness/gate.h):
# one rule for run's verdicts, last line and exit code, report's exit code and summaries, JUnit and
# diff (newuser11's findings). A run stopped by its CPU budget judged nothing past where it got: exit
# 1, a JUnit error, "stopped by the CPU budget" said, never "only analytic ran". A known failure
# names its entry's file and line; a stale one is said without failing; a tolerances file with a
# duplicate key or an unknown method is bad input, an unknown scenario name a warning, and
# MECHBENCH_TOLERANCES is honoured by run. diff: a known failure whose entry is gone is a
# regression, and the two reports' tolerance files are named.
set -u
exe=$1 data=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
tol=$data/tolerances
fail=0
expect() { grep -qE -- "$1" <<<"$out" || { echo "missing: $1"; fail=1; }; }
rc_is() { [ "$rc" = "$1" ] || { echo "$2: exit $rc, expected $1"; fail=1; }; }
done_part() { [ $fail = 0 ] || { echo "--- $1:"; echo "$out"; exit 1; }; echo "ok: $1"; }

# 1. Over budget: exit 1, the JUnit agrees (errors, no failure called a pass), the last line says so.
out=$("$exe" run fourbar_free s4_1_two_sliders --method analytic --method numeric --method dyn-ali3p \
        --budget 1e-300 --junit jb.xml 2>&1)
rc=$?
rc_is 1 "run --budget 1e-300"
expect 'stopped by the CPU budget \(--budget 1e-300 s\) before the end of the motion'
expect 'stopped by its CPU budget \(not judged past where it got: not a pass\)'
! grep -q 'only analytic ran;' <<<"$out" || { echo "'only analytic ran' while the others were stopped"; fail=1; }
! grep -q 'all methods agree' <<<"$out" || { echo "all methods agree with runs stopped by the budget"; fail=1; }
grep -qE '<error message="stopped by its CPU budget' jb.xml || { echo "JUnit: no error for a budget stop"; cat jb.xml; fail=1; }
done_part "over budget"

# 2. A known failure from the user's file names that file and line (verdict and JUnit); the same
# numbers without the entry fail.
out=$("$exe" run fourbar_free --method dyn-baumgarte-rk4 --method dyn-ali3p --tolerances "$tol/known_user.yaml" \
        --junit jk.xml 2>&1)
rc=$?
rc_is 0 "a known failure of the user's file"
expect "dyn-ali3p +known failure — held to 1e-15 on purpose \\($tol/known_user.yaml:9\\)"
grep -qF "known failure ($tol/known_user.yaml:9): held to 1e-15 on purpose" jk.xml ||
  { echo "JUnit: the known failure's file and line"; cat jk.xml; fail=1; }
done_part "known failure names its entry"
out=$("$exe" run fourbar_free --method dyn-baumgarte-rk4 --method dyn-ali3p --tolerances "$tol/tight_user.yaml" 2>&1)
rc=$?
rc_is 1 "the same bound without the known failure"
expect "^tolerances: harness/tolerances.yaml, then $tol/tight_user.yaml;"
done_part "the footer names the files used"

# 3. A stale known failure: said in the verdict and the last line, exit 0; an unknown scenario name
# in a user's file a warning with its line. Through MECHBENCH_TOLERANCES, which run honours.
out=$(MECHBENCH_TOLERANCES="$tol/stale_known.yaml" "$exe" run fourbar_free --method dyn-baumgarte-rk4 \
        --method dyn-ali3p 2>&1)
rc=$?
rc_is 0 "a stale known failure"
expect "dyn-baumgarte-rk4 +ok — known failure no longer fails: remove the entry \\($tol/stale_known.yaml:4: listed although it passes\\)"
expect "^known failure no longer fails: remove the entry: dyn-baumgarte-rk4 \\($tol/stale_known.yaml:4\\)"
expect "^warning: $tol/stale_known.yaml:6: scenario 'fourbar_fre' is none of the scenes given here nor a built-in one"
done_part "stale known failure, unknown scenario name, MECHBENCH_TOLERANCES"
out=$(MECHBENCH_TOLERANCES="$tol/bad_duplicate.yaml" "$exe" run fourbar_free --method dyn-ali3p 2>&1)
rc=$?
rc_is 2 "MECHBENCH_TOLERANCES naming a bad file"
expect "bad_duplicate.yaml:7: duplicate key 'dyn-ali3p'"
done_part "MECHBENCH_TOLERANCES read strictly by run"
out=$("$exe" run fourbar_free --method dyn-ali3p --tolerances "$tol/bad_method.yaml" 2>&1)
rc=$?
rc_is 2 "an unknown method in a tolerances file"
expect "bad_method.yaml:3: unknown method 'dyn-ali3pp' in a known failure"
done_part "unknown method refused"

# 4. diff: two reports of the same runs, the first judged with the known failure, the second
# without: a regression, and the files named.
common=(report fourbar_free --method dyn-ali3p --no-check --no-sweep --no-stress --no-precision --no-chains --jobs 1)
"$exe" "${common[@]}" --out r1 --tolerances "$tol/known_user.yaml" >r1.out 2>&1; rc=$?
out=$(cat r1.out)
rc_is 0 "report with the known failure"
expect '^  runs that are a known failure: 1$'
! grep -q '^  book values:$\|^  stress outcomes:$' <<<"$out" || { echo "empty summary lines"; fail=1; }
grep -qF "| \`fourbar_free\` | \`dyn-ali3p\` | known failure | known ($tol/known_user.yaml:9): held to 1e-15 on purpose; dyn-ali3p vs the reference: position error" r1/summary.md ||
  { echo "summary.md: the known failure's row"; cat r1/summary.md; fail=1; }
"$exe" "${common[@]}" --out r2 --tolerances "$tol/tight_user.yaml" >r2.out 2>&1; rc=$?
out=$(cat r2.out)
rc_is 1 "report without the known failure"
expect '^  runs outside their tolerance \(not known\): 1$'
grep -qE '^\| `fourbar_free` \| `dyn-ali3p` \| \*\*outside its tolerance\*\* \| dyn-ali3p vs the reference: position error [0-9.e+-]+ .* above 1e-15' r2/summary.md ||
  { echo "summary.md: the failing row's figure and bound"; cat r2/summary.md; fail=1; }
done_part "report: gate, summary lines, summary.md rows"
out=$("$exe" diff r1 r2 2>&1)
rc=$?
rc_is 1 "diff of a known failure that became a failure"
expect 'REGRESSION run/fourbar_free/dyn-ali3p: verdict known failure -> outside its tolerance'
expect "judged by different tolerance files: old harness/tolerances.yaml, then $tol/known_user.yaml; new harness/tolerances.yaml, then $tol/tight_user.yaml"
done_part "diff"

# 5. check: a claim not computed is not judged, not a pass (exit 1, said).
out=$("$exe" check "$data/scenes/crank_rocker_claims_at.yaml" 2>&1)
rc=$?
rc_is 1 "check with a claim not computed"
expect 'not computed, so not judged \(each row says why\): not a pass'
done_part "check: not computed"
