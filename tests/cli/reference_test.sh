#!/usr/bin/env bash
# Usage: reference_test.sh DEFORMKIT SCRATCH_DIR
# docs/deformers.md's generated section is exactly what `deformkit deformers --markdown` prints now, so the
# parameter reference in the docs cannot drift from the declarations it is made from.
set -u
dk=$1
work=$2
doc="$(cd "$(dirname "$0")/../.." && pwd)/docs/deformers.md"
rm -rf "$work" && mkdir -p "$work"
"$dk" deformers --markdown >"$work/generated.md" || { echo "FAIL: deformkit deformers --markdown"; exit 1; }
sed -n '/^<!-- BEGIN generated/,/^<!-- END generated -->/p' "$doc" | sed '1d;$d' >"$work/documented.md"
[ -s "$work/generated.md" ] || { echo "FAIL: nothing generated"; exit 1; }
if ! diff -u "$work/documented.md" "$work/generated.md"; then
    echo "FAIL: docs/deformers.md is out of date: run scripts/update_reference.py"
    exit 1
fi
# The terminal form lists every type the Markdown has.
"$dk" deformers >"$work/text.txt" || exit 1
for type in $(grep -oE '^### `[a-z]+`' "$work/generated.md" | tr -d '#` '); do
    grep -qx "$type" "$work/text.txt" || { echo "FAIL: deformkit deformers does not list $type"; exit 1; }
done
echo "reference: $(grep -c '^### ' "$work/generated.md") types, docs current"
