#!/usr/bin/python3
"""Counts test cases in JUnit XML files (gtest, rostest, Python) and prints `N passed, N failed`.

Usage: summarize_test_results.py DIR [DIR ...]. Exit status 1 when anything failed or no test ran.
"""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def count(path):
    passed, failed, names = 0, 0, []
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as e:
        return 0, 1, ["%s: unreadable result file (%s)" % (path, e)]
    for case in root.iter("testcase"):
        bad = case.find("failure") is not None or case.find("error") is not None
        skipped = case.find("skipped") is not None
        if case.get("status") == "notrun" or skipped:
            continue
        if bad:
            failed += 1
            # The failure's own message (first lines), so that a CI log says why, not only what.
            why = case.find("failure") if case.find("failure") is not None else case.find("error")
            text = " ".join(filter(None, [why.get("message"), why.text]))
            lines = [l for l in text.strip().splitlines() if l.strip()][-6:]
            names.append("%s.%s%s" % (case.get("classname"), case.get("name"),
                                      "".join("\n    " + l[:300] for l in lines)))
        else:
            passed += 1
    return passed, failed, names


def main(dirs):
    total_p, total_f, failures = 0, 0, []
    for d in dirs:
        for path in sorted(glob.glob(os.path.join(d, "**", "*.xml"), recursive=True)):
            p, f, names = count(path)
            total_p += p
            total_f += f
            failures += names
    for n in failures:
        print("FAILED: " + n)
    print("%d passed, %d failed" % (total_p, total_f))
    return 1 if total_f or total_p == 0 else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
