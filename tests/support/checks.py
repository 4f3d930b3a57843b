"""Check counting for the Python tests run by ctest: each check() counts, a failed one prints its
message and stops the current case; run_cases() runs every case and reports."""

import traceback


class CheckFailed(Exception):
    pass


class _Tally:
    passed = 0
    failed = 0


def check(cond, msg):
    """Counts one check; on failure prints the message and raises CheckFailed."""
    if cond:
        _Tally.passed += 1
        return
    _Tally.failed += 1
    print(f"FAIL: {msg}", flush=True)
    raise CheckFailed(msg)


def run_cases(name, cases, run):
    """Calls run(case) for each case (a dict with a "what" label), going on after a failure; a
    crash of the test itself counts as a failure. Prints the tally; returns the exit status."""
    failed_cases = []
    for c in cases:
        try:
            run(c)
        except CheckFailed:
            failed_cases.append(c["what"])
        except Exception as e:  # pylint: disable=broad-except
            _Tally.failed += 1
            failed_cases.append(c["what"])
            print(f"FAIL: {c['what']}: {type(e).__name__}: {e}")
            traceback.print_exc()
    if failed_cases:
        print(f"failed cases: {', '.join(failed_cases)}")
    print(f"{name}: {_Tally.passed} passed, {_Tally.failed} failed")
    return 1 if _Tally.failed else 0
