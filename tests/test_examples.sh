#!/bin/sh
# test_examples.sh - the example programs' behaviour at their edges (issue 18, item 17):
# an unknown argument is refused with a usage line and exit status 2; an output directory
# that cannot be written, or a standard output that cannot be (/dev/full), ends the program
# with a message and exit status 1 instead of a success; and the fast examples succeed in
# a writable directory. Prints PASS/FAIL per case and `RESULT <passed> <failed>` like the
# C tests (tests/test.h), so `make test` counts these cases in its total.
#
#   sh tests/test_examples.sh BUILD_EXAMPLES_DIR TMP_DIR [name-filter]
#
# Run by the Makefile as build/examples/test_examples.result; about 9 s (frames_connective
# runs twice, 2 s each).
bin=$1
tmp=$2
filter=$3
passed=0
failed=0
mkdir -p "$tmp" || exit 1
missing="$tmp/no/such/directory"

report() {
    name=$1; ok=$2; detail=$3
    if [ "$ok" -eq 0 ]; then
        passed=$((passed + 1)); echo "PASS $name"
    else
        failed=$((failed + 1)); echo "FAIL $name: $detail"
    fi
}

# run_case NAME EXPECTED_STATUS STDERR_PATTERN STDOUT_FILE -- command...
# passes when the command exits with EXPECTED_STATUS and its standard error matches
# STDERR_PATTERN (a grep -E pattern; empty: anything).
run_case() {
    name=$1; want=$2; pattern=$3; out=$4
    shift 5
    case "$name" in *"$filter"*) ;; *) return ;; esac
    "$@" > "$out" 2> "$tmp/stderr"
    got=$?
    ok=0; detail=""
    if [ "$got" -ne "$want" ]; then
        ok=1; detail="exit status $got, expected $want"
    elif [ -n "$pattern" ] && ! grep -Eq "$pattern" "$tmp/stderr"; then
        ok=1; detail="standard error does not match '$pattern'"
    fi
    [ "$ok" -ne 0 ] && sed 's/^/    stderr: /' "$tmp/stderr" | head -n 5
    report "$name" "$ok" "$detail"
}

# 1. unknown arguments: a usage line and exit status 2
run_case hello_bad_argument 2 '^usage' "$tmp/out" -- "$bin/tensormass_hello" bogus
run_case compression_bad_argument 2 '^usage' "$tmp/out" -- "$bin/heml_compression" bogus
run_case compression_two_arguments 2 '^usage' "$tmp/out" -- "$bin/heml_compression" nh svk
run_case beam_bad_option 2 '^usage' "$tmp/out" -- "$bin/frames_beam" --bogus
run_case beam_two_directories 2 '^usage' "$tmp/out" -- "$bin/frames_beam" "$tmp" "$tmp"
run_case cut_bad_option 2 '^usage' "$tmp/out" -- "$bin/tensormass_cut" --bogus
run_case hybrid_bad_option 2 '^usage' "$tmp/out" -- "$bin/tensormass_hybrid" --bogus
run_case hybrid_two_directories 2 '^usage' "$tmp/out" -- "$bin/tensormass_hybrid" "$tmp" "$tmp"
run_case connective_bad_option 2 '^usage' "$tmp/out" -- "$bin/frames_connective" --bogus
run_case connective_two_directories 2 '^usage' "$tmp/out" -- "$bin/frames_connective" "$tmp" "$tmp"
run_case soft_arm_bad_option 2 '^usage' "$tmp/out" -- "$bin/frames_soft_arm" --bogus
run_case link_compliance_bad_argument 2 '^usage' "$tmp/out" -- "$bin/heml_link_compliance" bogus
run_case soft_arm_two_directories 2 '^usage' "$tmp/out" -- "$bin/frames_soft_arm" "$tmp" "$tmp"

# 2. an output directory that does not exist: exit status 1, a message, no success claim
for e in frames_beam tensormass_cut tensormass_hybrid frames_soft_arm frames_connective; do
    run_case "${e}_missing_directory" 1 'cannot write' "$tmp/out" -- "$bin/$e" "$missing"
    case "${e}_missing_directory_claim" in *"$filter"*)
        if grep -q 'written\|wrote' "$tmp/out"; then
            report "${e}_missing_directory_claim" 1 "claims files were written: $(head -n 1 "$tmp/out")"
        else
            report "${e}_missing_directory_claim" 0 ""
        fi ;;
    esac
done

# 3. a standard output that cannot be written (a full disk): exit status 1
if [ -w /dev/full ]; then
    run_case hello_full_stdout 1 'failed' /dev/full -- "$bin/tensormass_hello"
    run_case compression_full_stdout 1 'failed' /dev/full -- "$bin/heml_compression" nh
    mkdir -p "$tmp/connective_full"
    run_case connective_full_stdout 1 'failed' /dev/full -- "$bin/frames_connective" "$tmp/connective_full"
else
    echo "(no /dev/full here: the full-disk cases are skipped)"
fi

# 4. the fast examples succeed and write what they say
run_case hello_runs 0 '' "$tmp/out" -- "$bin/tensormass_hello"
run_case compression_runs 0 '' "$tmp/curve.csv" -- "$bin/heml_compression" nh
case compression_csv in *"$filter"*)
    lines=$(wc -l < "$tmp/curve.csv")
    if head -n 1 "$tmp/curve.csv" | grep -q '^displacement_mm,force_N,closed_form_N$' && [ "$lines" -gt 30 ]; then
        report compression_csv 0 ""
    else
        report compression_csv 1 "$lines lines, header '$(head -n 1 "$tmp/curve.csv")'"
    fi ;;
esac
mkdir -p "$tmp/beam" "$tmp/hybrid" "$tmp/connective"
run_case beam_runs 0 '' "$tmp/out" -- "$bin/frames_beam" "$tmp/beam"
case beam_files in *"$filter"*)
    if [ -s "$tmp/beam/frames_beam_samples.vtk" ] && [ -s "$tmp/beam/frames_beam_frames.vtk" ] &&
        [ -s "$tmp/beam/frames_beam_render.vtk" ]; then
        report beam_files 0 ""
    else
        report beam_files 1 "the VTK files are missing or empty"
    fi ;;
esac
run_case link_compliance_runs 0 '' "$tmp/out" -- "$bin/heml_link_compliance"
mkdir -p "$tmp/arm"
run_case soft_arm_runs 0 '' "$tmp/out" -- "$bin/frames_soft_arm" "$tmp/arm"
case soft_arm_csv in *"$filter"*)
    lines=$(wc -l < "$tmp/arm/frames_soft_arm.csv" 2>/dev/null || echo 0)
    if head -n 1 "$tmp/arm/frames_soft_arm.csv" 2>/dev/null | grep -q '^path,step,time_s,target_x' && [ "$lines" -gt 1000 ] &&
        grep -q '^wrote .*frames_soft_arm.csv' "$tmp/out"; then
        report soft_arm_csv 0 ""
    else
        report soft_arm_csv 1 "$lines lines"
    fi ;;
esac
run_case hybrid_runs 0 '' "$tmp/out" -- "$bin/tensormass_hybrid" "$tmp/hybrid"
case hybrid_files in *"$filter"*)
    n=$(ls "$tmp/hybrid"/tensormass_hybrid_*.vtk 2>/dev/null | wc -l)
    if [ "$n" -eq 20 ] && grep -q "^20 VTK frames written" "$tmp/out"; then
        report hybrid_files 0 ""
    else
        report hybrid_files 1 "$n VTK files"
    fi ;;
esac

run_case connective_runs 0 '' "$tmp/out" -- "$bin/frames_connective" "$tmp/connective"
case connective_files in *"$filter"*)
    n=$(ls "$tmp/connective"/frames_connective_lower_*.vtk 2>/dev/null | wc -l)
    m=$(ls "$tmp/connective"/frames_connective_frames_*.vtk 2>/dev/null | wc -l)
    if [ "$n" -eq 25 ] && [ "$m" -eq 25 ] && grep -q "^25 VTK frames written" "$tmp/out" &&
        grep -q "per step .* ms: frames .* heml .* ms" "$tmp/out"; then
        report connective_files 0 ""
    else
        report connective_files 1 "$n + $m VTK files"
    fi ;;
esac

echo "RESULT $passed $failed"
[ "$failed" -eq 0 ]
