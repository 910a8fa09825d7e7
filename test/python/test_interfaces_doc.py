"""docs/interfaces.md, the repository's copy of the CLI/JSON contract (issue #23): every name of the
shared contract (../shared/spec/interfaces.md: backticked names and --options) is on it, and every
--option it names is in the --help of some subcommand of the built tool. Skipped without the tool;
the first check also without the shared contract."""
import os
import re
import subprocess
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
DOC = os.path.join(ROOT, "docs", "interfaces.md")
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "spec", "interfaces.md")
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
BUILT = os.path.exists(os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident"))
HELPS = [["simulate"], ["demod"], ["identify"], ["drift"], ["explain"], ["batch"]] + [
    [c, "--mode", m] for m in ("ringdown", "response") for c in ("identify", "explain", "simulate")]


def options(text):
    return set(re.findall(r"--[a-z][a-z0-9-]*", text))


class InterfacesDoc(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(DOC) as f:
            cls.doc = f.read()

    @unittest.skipUnless(os.path.exists(SHARED), "shared contract absent")
    def test_every_name_of_the_shared_contract_is_kept(self):
        with open(SHARED) as f:
            shared = f.read()
        names = set(re.findall(r"`([^`\n]+)`", shared)) | options(shared)
        missing = sorted(n for n in names if n not in self.doc)
        self.assertEqual(missing, [], "in the shared contract, not in docs/interfaces.md")

    @unittest.skipUnless(BUILT, "tool not built")
    def test_every_documented_option_exists(self):
        helps = ""
        for args in HELPS:
            p = subprocess.run([TOOL] + args + ["--help"], capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, " ".join(args))
            helps += p.stdout
        missing = sorted(options(self.doc) - options(helps) - {"--help"})
        self.assertEqual(missing, [], "named in docs/interfaces.md, in no subcommand's --help")


if __name__ == "__main__":
    unittest.main()
