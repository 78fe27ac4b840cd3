"""The python tests' assertion helper: `check(ok, what)` prints ok / FAIL and collects the
failures; a test ends with `sys.exit(1 if failures else 0)`."""
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)
