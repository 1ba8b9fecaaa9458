#!/usr/bin/env python3
"""Count test cases in the JUnit result files of `make run_tests`.

Prints every failing case with the first lines of its message, then one line
`N passed, N failed`; exits 1 unless
at least one test ran and none failed. A result file that cannot be parsed, or
a test binary that crashed (catkin writes a MISSING-... file), counts as failed.
"""
import pathlib
import sys
import xml.etree.ElementTree as ET

MESSAGE_LINES = 6


def main(root: str) -> int:
    passed = failed = skipped = 0
    files = sorted(pathlib.Path(root).rglob("*.xml"))
    for f in files:
        try:
            tree = ET.parse(f)
        except ET.ParseError as e:
            print(f"FAILED {f}: unreadable result file ({e})")
            failed += 1
            continue
        for case in tree.iter("testcase"):
            name = f"{case.get('classname', '')}.{case.get('name', '')}"
            problem = case.find("failure")
            if problem is None:
                problem = case.find("error")
            if problem is not None:
                print(f"FAILED {f.name}: {name}")
                # The message says which assert and with what values: a CI log that
                # keeps only its tail still shows why.
                text = (problem.get("message") or problem.text or "").strip().splitlines()
                for line in text[:MESSAGE_LINES]:
                    print(f"    {line[:300]}")
                failed += 1
            elif case.find("skipped") is not None or case.get("status") == "notrun":
                skipped += 1
            else:
                passed += 1
    line = f"{passed} passed, {failed} failed"
    if skipped:
        line += f", {skipped} skipped"
    print(line)
    return 0 if failed == 0 and passed > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "build/test_results"))
