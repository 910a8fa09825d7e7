"""Real ring-down exports of the development set (../shared/data/ringdowns_qpit_dev, tuning part of
scripts/validation/ringdown_real_split.csv only) that the tool of 26 Nov got wrong, each with the
instrument behaviour behind it; Q must come within 5 % of the authors' published Q:
- D014: the record starts at the floor before the drive comes on (a beat with Q 0.06x was called
  on a switch-off transient);
- D063: the decay ends in a curve the export appended (noiseless to the record's end; Q 5x);
- D141: the same after a glitch of three samples at the top of the scale (Q 9x);
- D293: the decay meets a floor that wanders (no floor found, an amplitude law called);
- D126: a step at switch-off;
- D146: a switch-off transient that undershoots the decay's line and comes back;
- D309, D145 (refused before 28 Nov): a decay followed by the drive on again, or by a clipped
  stretch at the drive level (the ring-down before it is read); D061: an amplitude law's Q is the span's mean decay; D204, D103: a
  tail that bends into a floor no rule confirmed; D197 (29 Nov, Q 0.36x): the drive toggled on
  again through 24-sample ramps, read as slopes; D060 (29 Nov, Q 0.79x): a switch-off transient
  whose beat was rightly rejected, and the two-stage decay behind it never tried.
Every Q interval must be positive and of non-zero width, and the span part of the uncertainty
must be reported. Skipped when the data or the tool is absent."""
import csv
import json
import os
import subprocess
import tempfile
import unittest

ROOT = os.path.abspath(os.environ.get("CVG_BENCH_ROOT",
                                      os.path.join(os.path.dirname(__file__), "..", "..")))
TOOL = os.path.join(ROOT, "bin", "cvg_ident")
DATA = os.environ.get("CVG_REAL_RINGDOWNS",
                      os.path.join(os.path.dirname(ROOT), "shared", "data", "ringdowns_qpit_dev"))
BUILT = os.path.exists(os.path.join(ROOT, "build", "ws", "devel", "lib", "cvg_bench", "cvg_ident"))


@unittest.skipUnless(BUILT and os.path.isdir(DATA), "tool not built or real records absent")
class RealRingdowns(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(os.path.join(DATA, "labels.csv")) as f:
            cls.labels = {r["id"]: r for r in csv.DictReader(f)}
        cls.tmp = tempfile.mkdtemp()

    def explain(self, rid):
        out = os.path.join(self.tmp, rid + ".json")
        p = subprocess.run([TOOL, "explain", os.path.join(DATA, "records", rid + ".txt"),
                            "--mode", "ringdown", "--json", out], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(out) as f:
            return json.load(f)

    def check(self, rid, why_part):
        j = self.explain(rid)
        q = j["final"]["derived_ci"]["Q"]
        qa = float(self.labels[rid]["authors_q"])
        why = j["final"]["segment"]["why"]
        self.assertLess(abs(q["value"] / qa - 1.0), 0.05, "%s: Q %g vs %g; %s" % (
            rid, q["value"], qa, why))
        self.assertIn(why_part, why)
        self.assertGreater(q["ci_low"], 0.0)
        self.assertGreater(q["ci_high"], q["ci_low"])
        self.assertGreater(q["std_total"], q["std_within"])
        return j

    def test_record_starting_at_the_floor(self):
        self.check("D014", "under the drive level")

    def test_appended_noiseless_tail(self):
        self.check("D063", "noiseless")

    def test_glitch_then_appended_tail(self):
        self.check("D141", "noiseless")

    def test_wandering_floor(self):
        j = self.check("D293", "meets a floor")
        self.assertEqual(j["selected"], [], j["cause"])

    def test_switch_off_step(self):
        self.check("D126", "at switch-off")

    def test_switch_off_transient(self):
        self.check("D146", "dips")

    def test_decay_then_drive_on_again(self):
        # Refused before 28 Nov: the highest drive-on stretch is the last, nothing decays after it;
        # since 28 Nov the ring-down before the drive came on again is read (it falls 20 dB more).
        self.check("D309", "before the drive came on again")

    def test_decay_then_clipped_stretch(self):
        # A clipped stretch at the drive level after the decay was read as a re-excitation; the
        # decay before it is read (28 Nov: it falls 20 dB more than what follows the stretch).
        self.check("D145", "before the drive came on again")

    def test_tail_bending_into_an_unconfirmed_floor(self):
        # No floor confirmed or suspected; the last quarter slows and scatters more: the span
        # ends where the level leaves the decay's line (Q was 1.16x / 1.06x with the tail).
        self.check("D204", "leaves the decay's line upwards")
        self.check("D103", "leaves the decay's line upwards")

    def test_amplitude_law_reports_the_spans_mean_decay(self):
        # gamma_nl selected on a clean decay: Q is the span's mean decay (Q_start was reported
        # before, 0.84x the authors'), Q0 above it.
        j = self.check("D061", "")
        d = j["final"]["derived_ci"]
        if "Q0" in d:
            self.assertGreater(d["Q0"]["value"], d["Q"]["value"])

    def test_drive_toggled_on_through_ramps(self):
        self.check("D197", "the drive comes on again at 62.64 s")

    def test_two_stage_tried_after_a_rejected_beat(self):
        j = self.check("D060", "")
        self.assertEqual(j["final"]["model"], "linear+two_stage")
        steps = {s["added"]: s for s in j["steps"]}
        self.assertIn("not the decay read off the record", steps["beat"]["note"])
        self.assertTrue(steps["two_stage"]["accepted"])

    def test_short_decay_above_its_floor_keeps_ten_db(self):
        # D008: 16 dB above a floor; the 10 dB margin left 3.2 dB of span (Q 1.75x). The margin
        # shrinks to leave 10 dB less the settling skip. Q is still 1.35x the authors' (their
        # window is not stored; the decay is curved): only the span is pinned here.
        j = self.explain("D008")
        seg = j["final"]["segment"]
        self.assertGreater(seg["decay_db"], 6.0, seg["why"])
        self.assertIn("fit ends 6.2", seg["why"])


if __name__ == "__main__":
    unittest.main()
