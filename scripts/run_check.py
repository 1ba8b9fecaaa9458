#!/usr/bin/env python3
"""Run one check command and record it as a JUnit test case.

Usage: run_check.py RESULTS_DIR NAME -- COMMAND [ARG ...]

Checks that are scripts rather than gtests (the installed package, the
fuzzers) land in the same result files as `make run_tests`, so that
count_results.py counts them with everything else. The command's output is
kept in the case's system-out; exit status 0 passes.
"""
import pathlib
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ET


def main(argv) -> int:
    if len(argv) < 4 or argv[2] != "--":
        print(__doc__)
        return 2
    results, name, command = pathlib.Path(argv[0]), argv[1], argv[3:]
    start = time.monotonic()
    proc = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
    elapsed = time.monotonic() - start
    sys.stdout.write(proc.stdout)
    # Terminal colour codes and other control characters are not allowed in XML.
    text = re.sub(r"\x1b\[[0-9;]*m|[\x00-\x08\x0b\x0c\x0e-\x1f]", "", proc.stdout)
    suite = ET.Element("testsuite", name=name, tests="1", failures="0" if proc.returncode == 0 else "1")
    case = ET.SubElement(suite, "testcase", classname="checks", name=name, time=f"{elapsed:.1f}")
    if proc.returncode != 0:
        ET.SubElement(case, "failure", message=f"exit status {proc.returncode}").text = text[-4000:]
    ET.SubElement(case, "system-out").text = text[-20000:]
    out = results / "checks"
    out.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(suite).write(out / f"check-{name}.xml", encoding="unicode", xml_declaration=True)
    print(f"check {name}: {'passed' if proc.returncode == 0 else 'FAILED'} ({elapsed:.0f} s)")
    return proc.returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
