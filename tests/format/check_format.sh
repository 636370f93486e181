#!/usr/bin/env bash
# check_format.sh SOURCE_DIR: lists every C++ file clang-format would change, and fails if there is one.
set -u
root=$1
if ! command -v clang-format >/dev/null 2>&1; then
    echo "SKIP: clang-format is not installed (scripts/setup.sh installs it)"
    exit 77
fi
cd "$root" || exit 1
mapfile -t files < <(find core plugins ptex_support tests -type f \( -name '*.cpp' -o -name '*.h' -o -name '*.inc' \) | sort)
# One process for every file; each violation is reported as "file:line:col: error: ...".
mapfile -t bad < <(clang-format --style=file --dry-run "${files[@]}" 2>&1 | grep -oE '^[^:]+:[0-9]+:[0-9]+: (error|warning):' |
    cut -d: -f1 | sort -u)
for f in "${bad[@]}"; do
    echo "not formatted: $f (clang-format -i $f)"
done
echo "${#files[@]} files checked, ${#bad[@]} not formatted"
[ "${#bad[@]}" -eq 0 ]
