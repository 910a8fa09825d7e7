"""Gates on the project's own code (issue #23): every tracked C++ file is as the repository's
.clang-format writes it (`make format` fixes it). The warning gate is in CMakeLists.txt
(-Werror with GCC on the project's sources). Skipped outside a git checkout or without
clang-format."""
import os
import shutil
import subprocess
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FORMAT = shutil.which("clang-format") or shutil.which("clang-format-14")


def tracked_cpp():
    p = subprocess.run(["git", "ls-files", "*.cpp", "*.h"], cwd=ROOT, capture_output=True,
                       text=True)
    return [f for f in p.stdout.split() if f] if p.returncode == 0 else []


@unittest.skipUnless(FORMAT and os.path.isdir(os.path.join(ROOT, ".git")),
                     "clang-format or git checkout absent")
class CodeGates(unittest.TestCase):
    def test_every_cpp_file_is_clang_formatted(self):
        files = tracked_cpp()
        self.assertGreater(len(files), 100)
        p = subprocess.run([FORMAT, "--dry-run", "--Werror"] + files, cwd=ROOT,
                           capture_output=True, text=True)
        bad = sorted({line.split(":")[0] for line in p.stderr.splitlines() if "error:" in line})
        self.assertEqual(p.returncode, 0, "not clang-formatted (run `make format`): %s" % bad)


if __name__ == "__main__":
    unittest.main()
