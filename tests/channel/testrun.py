"""The command line both channel test scripts share: run every test_* function of a module,
print PASS/FAIL/ERROR per test, exit non-zero if any failed (-k NAME runs a subset)."""
import argparse


def run_tests(namespace, doc):
    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    ap.add_argument("-k", help="run only the tests whose name contains this")
    a = ap.parse_args()
    tests = [(n, f) for n, f in namespace.items() if n.startswith("test_") and callable(f)]
    if a.k:
        tests = [(n, f) for n, f in tests if a.k in n]
    failed = 0
    for name, f in tests:
        try:
            f()
            print(f"PASS {name}")
        except AssertionError as e:
            failed += 1
            print(f"FAIL {name}: {e}")
        except Exception as e:  # a crash is a failure with its message
            failed += 1
            print(f"ERROR {name}: {type(e).__name__}: {e}")
    print(f"{len(tests) - failed}/{len(tests)} passed")
    return 1 if failed else 0
