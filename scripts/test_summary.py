#!/usr/bin/env python3
"""ctest's summary line with test cases counted, from ctest's full log (Testing/Temporary/LastTest.log).

A unit-test binary is one CTest entry that runs every Catch2 case of its area, and a pytest file is one
entry that runs every test in it; ctest's own summary would count each as one test. This prints ctest's line
counting their cases: every Catch2 case and every pytest case, and every other entry as one case. When the
run had sanitized entries (names "sanitized:..."), their own line comes first; the line for the whole run
is always the last.

    test_summary.py LAST_TEST_LOG
"""

import re
import sys

CATCH_PASSED = re.compile(r"^All tests passed \(\d+ assertions? in (\d+) test cases?\)", re.M)
CATCH_FAILED = re.compile(r"^test cases:\s*(\d+)\s*\|\s*(\d+) passed\s*\|\s*(\d+) failed", re.M)
PYTEST_LINE = re.compile(r"^=*\s*((?:\d+ \w+(?:, )?)+) in [\d.]+s", re.M)
ENTRY = re.compile(r"^\d+/\d+ Test: (.+)$", re.M)


def entry_counts(output, verdict):
    """(passed, failed, kind) test cases of one CTest entry from its output and ctest's verdict."""
    entry_passed = verdict == "Passed"
    m = CATCH_FAILED.search(output)
    if m:
        total, passed, failed = (int(g) for g in m.groups())
        return passed, max(failed, total - passed), "catch2"
    m = CATCH_PASSED.search(output)
    if m:
        cases = int(m.group(1))
        return (cases, 0, "catch2") if entry_passed else (0, max(cases, 1), "catch2")
    lines = PYTEST_LINE.findall(output)
    if lines:
        counts = dict((word, int(n)) for n, word in re.findall(r"(\d+) (\w+)", lines[-1]))
        failed = counts.get("failed", 0) + counts.get("error", 0) + counts.get("errors", 0)
        passed = counts.get("passed", 0) + counts.get("xfailed", 0) + counts.get("skipped", 0)
        if not entry_passed and failed == 0:
            failed = 1
        return passed, failed, "pytest"
    return (1, 0, "other") if entry_passed or verdict == "Skipped" else (0, 1, "other")


def summary(results):
    """ctest's line for `results`, a list of (passed, failed, kind, verdict) per entry."""
    passed = sum(r[0] for r in results)
    failed = sum(r[1] for r in results)
    kinds = {"catch2": 0, "pytest": 0, "other": 0}
    for p, f, kind, _ in results:
        kinds[kind] += p + f
    skipped = sum(r[3] == "Skipped" for r in results)
    total = passed + failed
    percent = 100 * passed // total if total else 0
    detail = (f"{kinds['catch2']} Catch2 cases, {kinds['pytest']} pytest cases, {kinds['other']} other "
              f"entries; {len(results)} CTest entries" + (f", {skipped} skipped" if skipped else ""))
    return f"{percent}% tests passed, {failed} tests failed out of {total} ({detail})"


def main():
    text = open(sys.argv[1], errors="replace").read()
    starts = [m for m in ENTRY.finditer(text)]
    results, sanitized = [], []
    for i, m in enumerate(starts):
        block = text[m.end():starts[i + 1].start() if i + 1 < len(starts) else len(text)]
        out = block.split("Output:", 1)[-1].split("<end of output>", 1)[0]
        verdict = "Passed" if "Test Passed." in block else ("Skipped" if "Skipped" in block else "Failed")
        result = (*entry_counts(out, verdict), verdict)
        results.append(result)
        if m.group(1).startswith("sanitized:"):
            sanitized.append(result)
    if sanitized:
        print("sanitized unit tests: " + summary(sanitized))
    print(summary(results))


if __name__ == "__main__":
    main()
