#!/usr/bin/python3
"""Runs the unittest-based Python tests in a directory and writes a JUnit XML file."""
import sys
import unittest
import xml.etree.ElementTree as ET


class _Recorder(unittest.TextTestResult):
    def __init__(self, *a, **k):
        super().__init__(*a, **k)
        self.records = []

    def addSuccess(self, test):
        super().addSuccess(test)
        self.records.append((test.id(), None))

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self.records.append((test.id(), self._exc_info_to_string(err, test)))

    def addError(self, test, err):
        super().addError(test, err)
        self.records.append((test.id(), self._exc_info_to_string(err, test)))

    def addSubTest(self, test, subtest, err):
        # A failing subTest fails its test (unittest then calls neither addSuccess nor
        # addFailure for the test itself): record it, or the summary would count nothing.
        super().addSubTest(test, subtest, err)
        if err is not None:
            self.records.append((subtest.id(), self._exc_info_to_string(err, subtest)))


def main(directory, out):
    suite = unittest.defaultTestLoader.discover(directory, pattern="test_*.py", top_level_dir=directory)
    runner = unittest.TextTestRunner(resultclass=_Recorder, verbosity=1)
    result = runner.run(suite)
    root = ET.Element("testsuite", name="python")
    for name, err in result.records:
        cls, _, meth = name.rpartition(".")
        case = ET.SubElement(root, "testcase", classname=cls, name=meth)
        if err:
            ET.SubElement(case, "failure").text = err
    ET.ElementTree(root).write(out)
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2]))
