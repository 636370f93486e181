"""What the headless Blender test scripts share: each runs its tests in order and exits 1 when one failed
(run_blender.sh turns Blender's exit code into the ctest result)."""

import sys
import tempfile
import traceback


def run(tests):
    """Calls each test with a scratch folder, prints PASS or FAIL with the traceback, then exits 1 on a
    failure. Every test runs whatever the others did."""
    failures = 0
    with tempfile.TemporaryDirectory() as folder:
        for test in tests:
            try:
                test(folder)
                print("PASS", test.__name__)
            except Exception:  # noqa: BLE001  (every test runs; each failure is printed)
                failures += 1
                print("FAIL", test.__name__)
                traceback.print_exc()
    if failures:
        sys.exit(1)
