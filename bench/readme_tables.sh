#!/bin/sh
# readme_tables.sh - prints the README's "Choosing a model" tables from a bench run's CSVs,
# so that the README is regenerated from bench/results after a full `make bench`, never
# typed by hand:
#
#   sh bench/readme_tables.sh [RESULTS_DIR]     (default bench/results)
#   sh bench/readme_tables.sh --update README.md [RESULTS_DIR]
#
# --update replaces, in the file given, each table whose header row starts like one of
# these tables' (its first 15 characters) with the regenerated one, and leaves every
# other line alone.
#
# 1. the speed/accuracy trade (trade.csv): per scene and header, the best error and the
#    cheapest configuration (seconds to the answer) under 10 % and 1 %; R2 (no closed form)
#    per variant in double: its finest level and the first level within 10 % / 1 % of it;
# 2. the largest stable time step (stability.csv, test max-dt, double);
# 3. the other extremes (stability.csv: poisson, squash, twist-180, far-origin);
# 4. the stress sweep (sweep.csv): per model entry, how many runs were right, returned an
#    error code, returned success with a wrong answer, or could not be judged;
# 5. the kernel ratios (kernels.csv, where it has the K*v-csr rows, issue 21): per model entry
#    and size, 1 thread, the force's share of its bandwidth bound, the force over its
#    arithmetic floor (arith rows), the differential over the CSR product.
# 6. the race to 1 % on R1 (race.csv, issue 21): per entry, where it first came within 1 %
#    (or its best within the budget), the solve's and the summed seconds.
# Errors are as the bench wrote them: R1 and R3 against the converged 3D solid, R3's
# frequency corrected for the integrator's phase error (bench.c, integrator_frequency).
# The prose around the tables quotes figures from them: check it after regenerating.
if [ "$1" = "--update" ]; then
    readme=$2
    [ -w "$readme" ] || { echo "readme_tables.sh: cannot update '$readme'" >&2; exit 1; }
    tables=$(mktemp) || exit 1
    out=$(mktemp) || exit 1
    sh "$0" ${3:+"$3"} > "$tables" || { rm -f "$tables" "$out"; exit 1; }
    # header signature -> table, then one pass over the README
    awk -v tables="$tables" '
    BEGIN {
        while ((getline line < tables) > 0) {
            if (line ~ /^\|/) {
                if (!intable) { sig = substr(line, 1, 15); intable = 1; text[sig] = "" }
                text[sig] = text[sig] line "\n"
            } else intable = 0
        }
    }
    skipping && /^\|/ { next }
    { skipping = 0 }
    /^\|/ && (substr($0, 1, 15) in text) && !done[substr($0, 1, 15)] {
        sig = substr($0, 1, 15); printf "%s", text[sig]; done[sig] = 1; skipping = 1; replaced++; next
    }
    { print }
    END { printf "readme_tables.sh: %d tables replaced\n", replaced > "/dev/stderr" }
    ' "$readme" > "$out" && cat "$out" > "$readme"
    rc=$?
    rm -f "$tables" "$out"
    exit $rc
fi
dir=${1:-bench/results}
for f in trade.csv stability.csv; do
    [ -r "$dir/$f" ] || { echo "readme_tables.sh: cannot read $dir/$f" >&2; exit 1; }
done

# shared awk helpers: percentages and durations as the README writes them
helpers='
function pct(e) { e = 100 * e; return (e < 1e-3 ? sprintf("%.1e", e) : sprintf("%.2g", e)) " %" }
function dur(t) {
    if (t >= 1) return sprintf("%.2f s", t)
    if (t >= 1e-3) return sprintf("%.1f ms", 1e3 * t)
    return sprintf("%.1f us", 1e6 * t)
}
function finite(x) { return x == x + 0 && x != "nan" && x != "-nan" && x != "inf" && x != "-inf" }
'

echo "Best error per model and the cheapest configuration (seconds to the answer) under 10 % and"
echo "1 % (R2: the finest level run and the first within 10 % / 1 % of it; double only):"
echo
awk -F, "$helpers"'
NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
{
    scene = $col["scene"]; model = $col["model"]; variant = $col["variant"]; prec = $col["precision"]
    setting = $col["setting"]; dof = $col["dof"]; t = $col["answer_s"] + 0; value = $col["value"]
    err = $col["error"]; status = $col["status"] + 0
    if (!(scene in seen_scene)) { seen_scene[scene] = 1; scenes[++nscenes] = scene }
    if (scene == "R2") {
        if (prec != "double" || status != 0) next
        key = scene SUBSEP model " " variant
        if (!(key in seen)) { seen[key] = 1; keys[scene, ++nkeys[scene]] = model " " variant }
        # the finest level is the one without an error (it is its own reference)
        if (!finite(err)) { fin_v[key] = value; fin_d[key] = dof; fin_t[key] = t; next }
        for (g = 1; g <= 2; g++) {
            goal = g == 1 ? 0.1 : 0.01
            if (err + 0 <= goal && (!((key, g) in cheap_t) || t < cheap_t[key, g])) {
                cheap_t[key, g] = t; cheap_d[key, g] = dof
            }
        }
        next
    }
    key = scene SUBSEP model
    if (!(key in seen)) { seen[key] = 1; keys[scene, ++nkeys[scene]] = model }
    if (status != 0 || !finite(err)) next
    label = variant " " prec " " setting
    if (!(key in best_e) || err + 0 < best_e[key]) {
        best_e[key] = err + 0; best_l[key] = label; best_d[key] = dof; best_t[key] = t
    }
    for (g = 1; g <= 2; g++) {
        goal = g == 1 ? 0.1 : 0.01
        if (err + 0 <= goal && (!((key, g) in cheap_t) || t < cheap_t[key, g])) {
            cheap_t[key, g] = t; cheap_l[key, g] = label; cheap_d[key, g] = dof
        }
    }
}
END {
    print "| scene | model | best error (DoF, time to answer) | first under 10 % | first under 1 % |"
    print "| --- | --- | --- | --- | --- |"
    for (s = 1; s <= nscenes; s++) {
        scene = scenes[s]
        for (k = 1; k <= nkeys[scene]; k++) {
            name = keys[scene, k]; key = scene SUBSEP name
            if (scene == "R2") {
                if (!(key in fin_v)) continue
                line = sprintf("| R2 | %s | finest level: tip %.3f m (%d DoF, %s) |", name, fin_v[key], fin_d[key],
                               dur(fin_t[key]))
                for (g = 1; g <= 2; g++)
                    line = line ((key, g) in cheap_t ? sprintf(" %s (%d DoF) |", dur(cheap_t[key, g]), cheap_d[key, g]) \
                                                      : " not within the levels run |")
                print line
                continue
            }
            if (!(key in best_e)) { print "| " scene " | " name " | no answer | not reached | not reached |"; continue }
            line = sprintf("| %s | %s | %s: %s, %d DoF, %s |", scene, name, pct(best_e[key]), best_l[key], best_d[key],
                           dur(best_t[key]))
            for (g = 1; g <= 2; g++)
                line = line ((key, g) in cheap_t ? sprintf(" %s (%s, %d DoF) |", dur(cheap_t[key, g]), cheap_l[key, g],
                                                           cheap_d[key, g]) : " not reached |")
            print line
        }
    }
}' "$dir/trade.csv"

echo
echo "Largest stable time step (\`stability.csv\`, test max-dt, double):"
echo
awk -F, '
NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
$col["test"] == "max-dt" && $col["precision"] == "double" {
    split($col["setting"], w, " "); integ = w[1]
    key = $col["model"] " " $col["variant"] " " $col["precision"] SUBSEP integ
    if (!(key in seen)) { seen[key] = 1; keys[++n] = key; ne[key] = 0 }
    v = $col["value"] + 0
    cell = $col["outcome"] == "stable-at-1s" ? ">= 1 s" : ($col["outcome"] == "unstable-at-1e-7s" ? \
           "< 1e-7 s" : sprintf("%.3g s", v))
    cells[key, ++ne[key]] = cell
    if (!(ne[key] in youngs)) youngs[ne[key]] = $col["parameter"] + 0
}
END {
    header = "| model | integrator |"; rule = "| --- | --- |"
    for (e = 1; e in youngs; e++) {
        y = youngs[e]
        header = header (e == 1 ? " largest stable dt, E =" : "") \
                 (y >= 1e6 ? sprintf(" %g MPa", y / 1e6) : y >= 1e3 ? sprintf(" %g kPa", y / 1e3) : \
                  sprintf(" %g Pa", y)) " |"
        rule = rule " --- |"
    }
    print header; print rule
    for (i = 1; i <= n; i++) {
        split(keys[i], kk, SUBSEP); line = "| " kk[1] " | " kk[2] " |"
        for (e = 1; e <= ne[keys[i]]; e++) line = line " " cells[keys[i], e] " |"
        print line
    }
}' "$dir/stability.csv"

echo
echo "The other extremes (\`stable\` = error under 10 %; \`error N\` = the library refused with code N):"
echo
awk -F, '
NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
function cell(   o) {
    o = $col["outcome"]
    if (o == "error-reported") return "error " $col["code"]
    if (o == "stable" || o == "visibly-wrong") return o " (" sprintf("%.2g", 100 * $col["error"]) " %)"
    return o
}
$col["test"] != "max-dt" {
    model = $col["model"] " " $col["variant"] " " $col["precision"]
    if (!(model in seen)) { seen[model] = 1; models[++n] = model }
    t = $col["test"]
    if (t == "poisson") {
        p = $col["parameter"] + 0
        if (!(p in seen_nu)) { seen_nu[p] = 1; nus[++nnu] = p }
        c[model, "nu" p] = cell()
    } else if (t == "squash") {
        split($col["setting"], w, " ")
        c[model, t] = (c[model, t] == "" ? "" : c[model, t] "; ") w[1] ": " cell()
    } else c[model, t] = cell()
}
END {
    header = "| model |"; rule = "| --- |"
    for (i = 1; i <= nnu; i++) { header = header (i == 1 ? " nu = " : " ") nus[i] " |"; rule = rule " --- |" }
    print header " squash (per integrator) | twist 180 | 1e6 m from origin |"
    print rule " --- | --- | --- |"
    for (m = 1; m <= n; m++) {
        line = "| " models[m] " |"
        for (i = 1; i <= nnu; i++) line = line " " c[models[m], "nu" nus[i]] " |"
        print line " " c[models[m], "squash"] " | " c[models[m], "twist-180"] " | " c[models[m], "far-origin"] " |"
    }
}' "$dir/stability.csv"

if [ -r "$dir/sweep.csv" ]; then
    echo
    echo "Stress sweep (\`sweep.csv\`; the grid and the judging are in bench.c, >>sweep): runs per model entry"
    echo "that converged to the right answer, returned an error code, returned success with a wrong"
    echo "answer, or could not be judged:"
    echo
    awk -F, '
    NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    {
        model = $col["model"] " " $col["variant"] " " $col["precision"]
        if (!(model in seen)) { seen[model] = 1; models[++n] = model }
        count[model, $col["outcome"]]++
        total[$col["outcome"]]++
    }
    END {
        print "| model | right | error code | success, wrong answer | unjudged |"
        print "| --- | --- | --- | --- | --- |"
        for (m = 1; m <= n; m++)
            printf "| %s | %d | %d | %d | %d |\n", models[m], count[models[m], "right"], count[models[m], "error"],
                   count[models[m], "WRONG"], count[models[m], "unjudged"]
        printf "| all | %d | %d | %d | %d |\n", total["right"], total["error"], total["WRONG"], total["unjudged"]
    }' "$dir/sweep.csv"
fi

if [ -r "$dir/kernels.csv" ] && grep -q ',K\*v-csr,' "$dir/kernels.csv"; then
    echo
    echo "Kernel ratios (\`kernels.csv\`, 1 thread, each ratio from rows of the same run): the force's"
    echo "share of its memory-bandwidth bound (bound / time), the force against its arithmetic alone"
    echo "(\`arith\`: the pass without gather and scatter), and the force differential against a CSR"
    echo "product of the same assembled tangent (\`K*v-csr\`, assembled by the bench):"
    echo
    awk -F, '
    NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    $col["threads"] == 1 {
        key = $col["model"] " " $col["variant"] " " $col["precision"] "|" $col["elements"]
        if (!(key in seen)) { seen[key] = 1; keys[++n] = key }
        ns[key, $col["kernel"]] = $col["ns_per_element"]
        if ($col["kernel"] == "force") bound[key] = $col["bound_ns_per_element"]
    }
    END {
        print "| model | elements | force ns | % of bound | force / arith | K*v ns | K*v / CSR |"
        print "| --- | --- | --- | --- | --- | --- | --- |"
        for (i = 1; i <= n; i++) {
            k = keys[i]
            if (ns[k, "K*v-csr"] == "" || ns[k, "force"] == "") continue
            split(k, p, "|")
            f = ns[k, "force"]; a = ns[k, "arith"]; kv = ns[k, "K*v"]; c = ns[k, "K*v-csr"]
            fa = "-"
            if (a > 0) fa = sprintf("%.2f", f / a)
            printf "| %s | %d | %.1f | %.0f %% | %s | %.1f | %.2f |\n", p[1], p[2], f, 100 * bound[k] / f, fa, kv, kv / c
        }
    }' "$dir/kernels.csv"
fi

if [ -r "$dir/race.csv" ]; then
    echo
    echo "The race to 1 % on R1 (\`race.csv\`, one run, one thread: each entry refined level by level,"
    echo "1 to 6 cells across, then 8, 10, ..., until within 1 % of the 3D solid or its budget spent;"
    echo "the solve's seconds, and every level's setup and solve summed up to it):"
    echo
    awk -F, "$helpers"'
    NR == 1 {
        for (i = 1; i <= NF; i++) col[$i] = i
        print "| race entry (R1, double) | within 1 % | cells across (DoF) | error | solve | summed |"
        print "| --- | --- | --- | --- | --- | --- |"
        next
    }
    {
        o = $col["outcome"]
        within = o == "reached" ? "yes" : "no (" (o == "budget" ? "budget " $col["budget_s"] " s" : o) "): best"
        name = $col["model"] " " $col["variant"]
        if ($col["dof"] + 0 == 0) { printf "| %s | %s | - | - | - | - |\n", name, within; next }
        printf "| %s | %s | %d (%d) | %s | %s | %s |\n", name, within, $col["level"], $col["dof"], pct($col["error"]),
               dur($col["solve_s"]), dur($col["cumulative_s"])
    }' "$dir/race.csv"
fi
