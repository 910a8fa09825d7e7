#!/usr/bin/python3
"""rostest: record -> replay round trip to the printed digits (issue #27).

The live simulated chain (bench_sim.launch: simulator -> demodulator -> identifier under /cvg) runs
one short free decay while launch/record.launch records it (started by this test as
`roslaunch cvg_bench record.launch bag:=...`, stopped with SIGINT as Ctrl-C stops it, so the bag is
closed: no .bag.active is left). The bag is then replayed with launch/replay.launch as a user runs
it (`roslaunch cvg_bench replay.launch bag:=... ns:=replay`: scripts/replay_player.py plays the
bag's /cvg/raw and /cvg/truth into /replay, a fresh demodulator and identifier there, simulated
time). Asserted:
- no input lost, by sequence numbers and counts: the live demodulator and identifier lost
  nothing; the bag holds the replay's whole input, every raw batch the simulator published
  (header.seq 0..N-1 plus the empty end-of-record batch) and the experiment's truth; the replay's
  demodulator receives every raw sample and makes as many slow states as the live one, the
  replay's identifier receives them all, neither counts a loss, and no estimate carries a
  lost-input reason;
- the recorded /cvg/slow (kept for comparison, not replayed) may miss messages: rosbag record
  subscribes with a fixed queue of 100 messages and the demodulator publishes a burst per raw
  batch; every missing one must show as a missing sequence number (counted in the JSON line);
- the replayed final estimate of the experiment equals the live one to the digits the tools print:
  every parameter value as `cvg_ident identify` prints it ('%.8g'), its interval ('%.6g'),
  sigma-hat, omega, the sample count and window stamps, and the derived Q, frequency error,
  frequency split, zero-rate and damping anisotropy (value '%.8g', interval '%.6g');
- the bag's own last /cvg/estimate (what the live identifier published, recorded for comparison)
  prints the same as the live final estimate.
The figures are printed as a ROUNDTRIP JSON line (and appended to $CVG_LOAD_REPORT when set);
CVG_ROUNDTRIP_KEEP=1 keeps the bag and the launches' logs (the path is printed)."""
import json
import os
import shutil
import signal
import subprocess
import tempfile
import threading
import time
import unittest
import xmlrpc.client

import rosbag
import rosgraph
import rosnode
import rospy
import rostest

from cvg_bench.msg import DerivedQuantitiesStamped, ModelEstimate
from cvg_bench.srv import StartFreeDecay
from diagnostic_msgs.msg import DiagnosticArray

LIVE, REPLAY = "cvg", "replay"
RECORDED = ["/cvg/raw", "/cvg/truth", "/cvg/slow", "/cvg/sweep", "/cvg/estimate"]  # record.launch
DERIVED = ["Q", "frequency_error_hz", "frequency_split_hz", "zero_rate_rad_s",
           "damping_anisotropy_1_s"]
SAMPLE_RATE_HZ = 300000.0  # mems_ring raw_sample_rate_hz


def printed(est, derived):
    """The estimate as the tools print it: {quantity: string}."""
    p = {"n_samples": str(est.n_samples), "model": est.model, "method": est.method,
         "experiment_id": str(est.experiment_id), "omega_rad_s": "%.9g" % est.omega_rad_s,
         "sigma": "%.8g" % est.sigma, "window_start": str(est.window_start),
         "window_end": str(est.window_end), "experiment_start": str(est.experiment_start),
         "suspect": str(est.suspect), "sanity_problems": "; ".join(est.sanity_problems)}
    for name, v, lo, hi in zip(est.names, est.values, est.ci_low, est.ci_high):
        p[name] = "%.8g" % v
        p[name + " interval"] = "[%.6g, %.6g]" % (lo, hi)
    for key in DERIVED:
        p[key] = "%.8g" % getattr(derived, key)
        p[key + " interval"] = "[%.6g, %.6g]" % (getattr(derived, key + "_ci_low"),
                                                getattr(derived, key + "_ci_high"))
    return p


class Chain(object):
    """Estimates, derived quantities and diagnostics of the nodes under one namespace."""

    def __init__(self, ns):
        self.ns = ns
        self.lock = threading.Lock()
        self.estimates = []  # (msg, monotonic time)
        self.derived = []
        self.diag = {}
        self.subs = [
            rospy.Subscriber("/%s/estimate" % ns, ModelEstimate, self.on_estimate,
                             queue_size=100),
            rospy.Subscriber("/%s/derived" % ns, DerivedQuantitiesStamped, self.on_derived,
                             queue_size=100),
            rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diag, queue_size=100)]

    def on_estimate(self, msg):
        with self.lock:
            self.estimates.append((msg, time.monotonic()))

    def on_derived(self, msg):
        with self.lock:
            self.derived.append(msg)

    def on_diag(self, msg):
        with self.lock:
            for st in msg.status:
                node = st.name.split(":")[0]  # "<ns>/<node>: <task>" (diagnostic_updater)
                if node.startswith(self.ns + "/"):
                    values = {kv.key: kv.value for kv in st.values}
                    values["summary"] = st.message
                    values["wall"] = time.monotonic()
                    self.diag[node[len(self.ns) + 1:]] = values

    def final(self, experiment_id):
        """(last estimate of the experiment, its derived quantities, its arrival time)."""
        with self.lock:
            mine = [e for e in self.estimates if e[0].experiment_id == experiment_id]
            if not mine:
                return None, None, None
            est, wall = mine[-1]
            derived = [d for d in self.derived if d.header.stamp == est.window_end]
            return est, (derived[-1] if derived else None), wall

    def close(self):
        for s in self.subs:
            s.unregister()


def connected(node, topics):
    """True when `node` has an incoming connection from a publisher of every topic (its bus
    info; registration with the master alone precedes the TCP connection)."""
    try:
        uri = rosnode.get_api_uri(rosgraph.Master("/record_replay_roundtrip"), node)
        if not uri:
            return False
        info = xmlrpc.client.ServerProxy(uri).getBusInfo("/record_replay_roundtrip")[2]
    except (OSError, rosnode.ROSNodeIOException, xmlrpc.client.Error):
        return False  # not up yet
    # Rows: [connection id, peer, direction, transport, topic, connected, ...].
    have = {c[4] for c in info if c[2] == "i" and (len(c) < 6 or c[5])}
    return all(t in have for t in topics)


def stop_launch(proc, timeout_s):
    """Ctrl-C for a roslaunch started by this test (its own process id only)."""
    if proc is not None and proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout_s)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(10)


class RecordReplayRoundtrip(unittest.TestCase):
    def setUp(self):
        self.maxDiff = None  # a failure shows every printed quantity that differs
        self.tmp = tempfile.mkdtemp(prefix="cvg_roundtrip_", dir="/tmp")
        self.bag = os.path.join(self.tmp, "run.bag")
        self.recorder = None
        self.replay = None
        self.logs = []
        self.live = Chain(LIVE)

    def tearDown(self):
        stop_launch(self.recorder, 30.0)
        stop_launch(self.replay, 30.0)
        self.live.close()
        for log in self.logs:
            log.close()
        if os.environ.get("CVG_ROUNDTRIP_KEEP"):  # the bag and the launches' logs, to look into
            print("ROUNDTRIP kept " + self.tmp)
        else:
            shutil.rmtree(self.tmp, ignore_errors=True)

    def wait(self, what, timeout_s, message):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline and not rospy.is_shutdown():
            if what():
                return
            time.sleep(0.1)  # poll period of the bounded wait
        self.fail(message)

    def roslaunch(self, launch_file, *args):
        log = open(os.path.join(self.tmp, launch_file + ".log"), "w")
        self.logs.append(log)
        return subprocess.Popen(["roslaunch", "cvg_bench", launch_file] + list(args),
                                stdout=log, stderr=subprocess.STDOUT, start_new_session=True)

    def settled(self, chain, experiment_id, n_samples):
        """The experiment's final estimate: over n_samples (None: any), nothing newer for 2 s,
        and diagnostics of both nodes published since."""
        est, derived, wall = chain.final(experiment_id)
        if est is None or derived is None or time.monotonic() - wall < 2.0:
            return False
        if n_samples is not None and est.n_samples != n_samples:
            return False
        with chain.lock:
            return all(k in chain.diag and chain.diag[k]["wall"] > wall + 0.5
                       for k in ("demodulator", "identifier"))

    def test_replay_prints_the_live_digits(self):
        timing = {}
        t_start = time.monotonic()
        duration_s = rospy.get_param("~duration_s", 1.0)
        rospy.wait_for_service("/cvg/start_free_decay", 20.0)
        rospy.wait_for_service("/cvg/identify", 20.0)

        # 1. Record, as launch/record.launch records (its topic list, its buffer).
        self.recorder = self.roslaunch("record.launch", "bag:=" + self.bag)
        self.wait(lambda: connected("/recorder_cvg", RECORDED), 30.0,
                  "record.launch's recorder is not connected to every publisher of %s" % RECORDED)

        # 2. A live experiment, to its settled final estimate.
        self.wait(lambda: "resonator_simulator" in self.live.diag, 10.0, "no simulator diagnostics")
        start = rospy.ServiceProxy("/cvg/start_free_decay", StartFreeDecay)
        self.assertTrue(start(duration_s=duration_s, seed=5).success)

        def live_done():
            sim = self.live.diag.get("resonator_simulator")
            demod = self.live.diag.get("demodulator")
            return (sim is not None and sim["summary"] == "finished"
                    and int(sim["experiments_started"]) == 1 and demod is not None
                    and float(demod["input_rate_samples_per_s"]) == 0.0
                    and self.settled(self.live, 1, int(demod["slow_states_published"])))
        self.wait(live_done, 60.0, "the live experiment did not finish and settle")
        timing["live_s"] = round(time.monotonic() - t_start, 1)
        live_est, live_derived, _ = self.live.final(1)
        with self.live.lock:
            sim = dict(self.live.diag["resonator_simulator"])
            demod = dict(self.live.diag["demodulator"])
            ident = dict(self.live.diag["identifier"])
        n_raw = int(duration_s * SAMPLE_RATE_HZ) + 1
        raw_batches = int(sim["raw_batches_published"])
        slow_published = int(demod["slow_states_published"])
        self.assertEqual(int(sim["raw_samples_published"]), n_raw, sim)
        self.assertEqual(int(demod["raw_samples_received"]), n_raw, demod)
        self.assertEqual(int(demod["batches_lost_in_transport"]), 0, demod)
        self.assertEqual(int(demod["end_of_record_markers"]), 1, demod)
        self.assertEqual(int(ident["received"]), slow_published, ident)
        self.assertEqual(int(ident["dropped_in_transport"]), 0, ident)
        self.assertEqual(live_est.n_samples, slow_published)
        self.assertFalse(live_est.suspect, live_est.sanity_problems)

        # 3. Stop the recorder as Ctrl-C does: rosbag record closes the bag (.active renamed).
        t_stop = time.monotonic()
        stop_launch(self.recorder, 40.0)
        self.assertEqual(self.recorder.returncode, 0, "record.launch did not stop cleanly")
        self.assertFalse(os.path.exists(self.bag + ".active"), "the bag was left .active")
        self.assertTrue(os.path.exists(self.bag), "no bag written")
        timing["recorder_stop_s"] = round(time.monotonic() - t_stop, 1)

        # The bag holds the replay's input whole (raw batches, truth), numbered without a gap.
        seqs = {}
        bag_estimates = []
        with rosbag.Bag(self.bag) as bag:
            for topic, msg, _ in bag.read_messages():
                seqs.setdefault(topic, []).append(msg.header.seq)
                if topic == "/cvg/estimate":
                    bag_estimates.append(msg)
        raw_seq = seqs.get("/cvg/raw", [])
        self.assertEqual(raw_seq, list(range(raw_batches + 1)),
                         "raw batches in the bag: %d of %d + end marker" % (len(raw_seq),
                                                                           raw_batches))
        self.assertEqual(len(seqs.get("/cvg/truth", [])), 1)
        # The recorded slow states are not replayed (the demodulator makes them afresh), only kept
        # for comparison; what the recorder lost of them must show as missing sequence numbers.
        slow_seq = seqs.get("/cvg/slow", [])
        self.assertTrue(slow_seq, "no /cvg/slow in the bag")
        self.assertEqual(slow_seq, sorted(set(slow_seq)))
        slow_missing = slow_seq[0] + sum(b - a - 1 for a, b in zip(slow_seq, slow_seq[1:]))
        self.assertEqual(len(slow_seq) + slow_missing, slow_published,
                         "recorded /cvg/slow: lost messages not visible by sequence number")
        self.assertTrue(bag_estimates, "no /cvg/estimate in the bag")
        live_printed = printed(live_est, live_derived)
        self.assertEqual(printed(bag_estimates[-1], live_derived), live_printed,
                         "the bag's last /cvg/estimate is not the live final estimate")

        # 4. Replay as a user does: launch/replay.launch, into /replay.
        replay = Chain(REPLAY)
        t_replay = time.monotonic()
        try:
            self.replay = self.roslaunch("replay.launch", "bag:=" + self.bag, "ns:=" + REPLAY)

            def replay_done():
                return (self.replay.poll() is None
                        and not rospy.get_param("/use_sim_time", True)  # the player finished
                        and self.settled(replay, 1, live_est.n_samples))
            self.wait(replay_done, 60.0,
                      "no settled replay estimate over %d slow states" % live_est.n_samples)
            timing["replay_s"] = round(time.monotonic() - t_replay, 1)
            rep_est, rep_derived, _ = replay.final(1)
            with replay.lock:
                rdemod = dict(replay.diag["demodulator"])
                rident = dict(replay.diag["identifier"])
        finally:
            replay.close()
        stop_launch(self.replay, 40.0)

        # Nothing lost on the replay side.
        self.assertEqual(int(rdemod["raw_samples_received"]), n_raw, rdemod)
        self.assertEqual(int(rdemod["batches"]), raw_batches + 1, rdemod)
        self.assertEqual(int(rdemod["batches_lost_in_transport"]), 0, rdemod)
        self.assertEqual(int(rdemod["end_of_record_markers"]), 1, rdemod)
        self.assertEqual(int(rdemod["slow_states_published"]), slow_published, rdemod)
        self.assertEqual(int(rident["received"]), slow_published, rident)
        self.assertEqual(int(rident["dropped_in_transport"]), 0, rident)
        self.assertEqual(int(rident["experiment_id"]), 1, rident)
        self.assertFalse([p for p in rep_est.sanity_problems if "lost" in p],
                         rep_est.sanity_problems)

        replay_printed = printed(rep_est, rep_derived)
        differ = {k: (v, replay_printed.get(k)) for k, v in live_printed.items()
                  if replay_printed.get(k) != v}
        report = {"duration_s": duration_s, "raw_samples": n_raw, "raw_batches": raw_batches,
                  "slow_states": slow_published, "bag_slow_states": len(slow_seq),
                  "bag_slow_missing_by_seq": slow_missing,
                  "bag_mb": round(os.path.getsize(self.bag) / 1e6, 1),
                  "gamma": live_printed["gamma"], "Q": live_printed["Q"],
                  "frequency_error_hz": live_printed["frequency_error_hz"],
                  "frequency_split_hz": live_printed["frequency_split_hz"],
                  "printed_quantities": len(live_printed), "differ": differ, "timing": timing,
                  "wall_s": round(time.monotonic() - t_start, 1)}
        print("ROUNDTRIP " + json.dumps(report))
        if os.environ.get("CVG_LOAD_REPORT"):
            with open(os.environ["CVG_LOAD_REPORT"], "a") as f:
                f.write(json.dumps({"roundtrip": report}) + "\n")
        self.assertEqual(replay_printed, live_printed)


if __name__ == "__main__":
    rospy.init_node("record_replay_roundtrip")
    rostest.rosrun("cvg_bench", "record_replay_roundtrip", RecordReplayRoundtrip)
