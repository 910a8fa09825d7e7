"""scripts/replay_player.py's choices without a roscore: which topics a replay plays (the input the
nodes do not remake) and how many messages a recording dropped (missing sequence numbers)."""
import importlib.util
import os
import unittest

ROOT = os.environ.get("CVG_BENCH_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
spec = importlib.util.spec_from_file_location(
    "replay_player", os.path.join(ROOT, "scripts", "replay_player.py"))
player = importlib.util.module_from_spec(spec)
spec.loader.exec_module(player)


class ReplayPlayer(unittest.TestCase):
    def test_raw_bag_plays_the_input_and_leaves_recorded_slow_out(self):
        play, left = player.choose_topics(
            {"/cvg/raw", "/cvg/truth", "/cvg/slow", "/cvg/estimate"}, "auto")
        self.assertEqual(play, ["/cvg/raw", "/cvg/truth"])
        play, _ = player.choose_topics({"/cvg/raw", "/cvg/sweep"}, "auto")  # sweeps are not remade
        self.assertEqual(play, ["/cvg/raw", "/cvg/sweep"])
        self.assertIn("/cvg/slow", dict(left))
        self.assertIn("afresh", dict(left)["/cvg/slow"])
        self.assertIn("/cvg/estimate", dict(left))

    def test_slow_bag_feeds_the_identifier(self):
        play, _ = player.choose_topics({"/cvg/slow"}, "auto")
        self.assertEqual(play, ["/cvg/slow"])
        play, left = player.choose_topics({"/cvg/raw", "/cvg/slow"}, "false")
        self.assertEqual(play, ["/cvg/slow"])
        self.assertIn("/cvg/raw", dict(left))
        play, _ = player.choose_topics({"/cvg/slow"}, "true")  # demodulator asked for, no raw
        self.assertEqual(play, [])

    def test_missing_by_sequence(self):
        self.assertEqual(player.missing_by_sequence([0, 1, 2, 3]), 0)
        self.assertEqual(player.missing_by_sequence([0, 1, 5, 6, 9]), 5)
        self.assertEqual(player.missing_by_sequence([0, 0, 0]), 0)      # no numbers
        self.assertEqual(player.missing_by_sequence([7, 8, 0, 1]), 0)   # a restarted publisher


if __name__ == "__main__":
    unittest.main()
