#!/bin/sh
# avx2_symbols.sh <nm> <objects>: <objects> is a ;-separated list (CMake's) of the AVX2 kernel files'
# objects. Fails when one defines a weak or unique symbol (an inline function, a template instantiation):
# the linker keeps one copy of such a symbol for the whole program, maybe the AVX2 one, and a CPU without
# AVX2 would then run it from the baseline code.
nm=$1
checked=0
status=0
IFS=';'
set -f
for object in $2; do
    checked=$((checked + 1))
    if [ ! -f "$object" ]; then
        echo "$object: not built"
        status=1
        continue
    fi
    shared=$("$nm" -C --defined-only "$object" | grep -E '^[0-9a-fA-F]* +[VvWwu] ')
    if [ -n "$shared" ]; then
        echo "$object defines symbols the linker may share:"
        echo "$shared"
        status=1
    fi
done
if [ "$checked" -eq 0 ]; then
    echo "no AVX2 kernel objects given"
    exit 1
fi
echo "$checked AVX2 kernel objects checked"
exit $status
