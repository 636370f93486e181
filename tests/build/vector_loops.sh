#!/bin/sh
# vector_loops.sh <objdump> <object>: <object> is the UV-warp solver's AVX2 kernel object. Fails unless each
# of its projection and regularisation loops (projectRow, regulariseRun: 8 + 2 instantiations) was compiled
# to 8-lane AVX2 arithmetic: packed square roots on ymm registers in every projectRow (counted with the
# functions GCC splits out of it, its block lambda), packed multiplies on ymm registers in every
# regulariseRun. GCC falls back to scalar code, silently, when one statement of a loop cannot be vectorised
# (a select between two comparisons did once, at 2.2 times the cost of a frame).
objdump=$1
object=$2
if [ ! -f "$object" ]; then
    echo "$object: not built"
    exit 1
fi
"$objdump" -d -C --no-show-raw-insn "$object" | awk '
    /^[0-9a-f]+ <.*>:$/ {
        name = $0
        sub(/^[0-9a-f]+ </, "", name)
        kind = ""
        if (match(name, /projectRow<[^>]*>/)) { kind = "projection"; name = substr(name, RSTART, RLENGTH) }
        else if (match(name, /regulariseRun<[^>]*>/)) { kind = "regularisation"; name = substr(name, RSTART, RLENGTH) }
        if (kind != "") { kinds[name] = kind; if (!(name in packed)) packed[name] = 0 }
        next
    }
    kind == "projection" && /vsqrtps.*%ymm/ { packed[name]++ }
    kind == "regularisation" && /vmulps.*%ymm/ { packed[name]++ }
    END {
        found = 0; failed = 0
        for (n in kinds) {
            found++
            if (packed[n] == 0) {
                failed = 1
                print "scalar " kinds[n] " loop (no 8-lane " (kinds[n] == "projection" ? "square root" : "multiply") "): " substr(n, 1, 160)
            }
        }
        if (found != 10) { print "expected 10 kernel loops (8 projectRow, 2 regulariseRun), found " found; failed = 1 }
        if (!failed) print found " kernel loops compiled to 8-lane AVX2 arithmetic"
        exit failed
    }'
