#!/usr/bin/python3
"""Replays a recorded bench run for launch/replay.launch: plays only what the nodes do not make
themselves, with a queue that holds the whole bag, and restores wall time when it ends.

- Topics: with the demodulator running (`--demodulate true`, or `auto` and raw batches in the bag)
  `/cvg/raw` and `/cvg/truth`; a recorded `/cvg/slow` is left out (the demodulator makes it afresh:
  played too, two streams would mix). Without it `/cvg/slow`, `/cvg/sweep` and `/cvg/truth`.
- Messages missing by header sequence number (the recording dropped them) are counted per topic
  and logged before the replay starts.
- `rosbag play --clock --queue=N` once the identifier's services answer (start-up order loses
  nothing); on exit (end of the bag, Ctrl-C, roslaunch shutdown) `/use_sim_time` is set back to
  false, so the next launch on this master runs on wall time.

  replay_player.py BAG [--rate R] [--loop true|false] [--delay S] [--demodulate auto|true|false] [--ns NS]
"""
import argparse
import subprocess
import sys

RAW, SLOW, SWEEP, TRUTH = "/cvg/raw", "/cvg/slow", "/cvg/sweep", "/cvg/truth"
QUEUE = 1000000  # messages; rosbag's default of 100 drops a burst silently


def choose_topics(bag_topics, demodulate):
    """(topics to play, [(topic, why left out)]) for the bag's topic names."""
    run_demod = demodulate == "true" or (demodulate == "auto" and RAW in bag_topics)
    # Sweep points are never remade by the demodulator: played in both cases.
    wanted = [RAW, SWEEP, TRUTH] if run_demod else [SLOW, SWEEP, TRUTH]
    play = [t for t in wanted if t in bag_topics]
    left = []
    for t in sorted(bag_topics):
        if t in play:
            continue
        if t == SLOW and run_demod:
            left.append((t, "the demodulator makes it afresh from /cvg/raw"))
        elif t == RAW:
            left.append((t, "no demodulator (demodulate:=false)"))
        else:
            left.append((t, "not an input of the nodes"))
    return play, left


def missing_by_sequence(seqs):
    """Messages skipped in a publisher's numbering (0 when the messages carry no numbers)."""
    missing = 0
    for a, b in zip(seqs, seqs[1:]):
        if b > a:
            missing += b - a - 1
    return missing


def scan_bag(path, topics=None):
    """{topic: message count} and {topic: missing by sequence} over `topics` (none read when
    topics is empty; all when None)."""
    import rosbag
    counts, seqs = {}, {}
    with rosbag.Bag(path) as bag:
        info = bag.get_type_and_topic_info().topics
        for name, t in info.items():
            counts[name] = t.message_count
        if topics is not None and not topics:
            return counts, {}
        for topic, msg, _ in bag.read_messages(topics=list(info) if topics is None else topics):
            header = getattr(msg, "header", None)
            if header is not None:
                seqs.setdefault(topic, []).append(header.seq)
    return counts, {t: missing_by_sequence(s) for t, s in seqs.items()}


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bag")
    ap.add_argument("--rate", type=float, default=1.0)
    ap.add_argument("--loop", type=str.lower, choices=["true", "false", "1", "0"],
                    default="false")
    ap.add_argument("--delay", type=float, default=1.0)
    ap.add_argument("--demodulate", type=str.lower, choices=["auto", "true", "false", "1", "0"],
                    default="auto")
    ap.add_argument("--ns", default="cvg")
    args, _ = ap.parse_known_args(argv)
    args.demodulate = {"1": "true", "0": "false"}.get(args.demodulate, args.demodulate)
    args.loop = {"1": "true", "0": "false"}.get(args.loop, args.loop)
    import rospy
    rospy.init_node("player", disable_signals=True)
    counts, _ = scan_bag(args.bag, topics=[])
    play, left = choose_topics(set(counts), args.demodulate)
    if args.demodulate == "true" and RAW not in counts:
        rospy.logwarn("replay: demodulate:=true but %s has no %s: the demodulator gets nothing",
                      args.bag, RAW)
    if not play:
        rospy.logerr("replay: %s holds none of %s; its topics: %s", args.bag,
                     ", ".join([RAW, SLOW, SWEEP]), ", ".join(sorted(counts)) or "none")
        return 2
    _, missing = scan_bag(args.bag, topics=play)
    rospy.loginfo("replay: playing %s from %s", ", ".join("%s (%d)" % (t, counts[t]) for t in play),
                  args.bag)
    for t, why in left:
        rospy.loginfo("replay: %s left out: %s", t, why)
    for t, n in sorted(missing.items()):
        if n:
            where = ("the demodulator announces them (InputLoss) and the identifier marks "
                     "estimates over them suspect" if t == RAW
                     else "the identifier marks estimates over them suspect")
            rospy.logwarn("replay: %s: %d messages missing by sequence number (the recording "
                          "dropped them); %s", t, n, where)
    service = "/%s/identify" % args.ns.strip("/")
    try:
        rospy.wait_for_service(service, 30.0)
    except rospy.ROSException:
        rospy.logwarn("replay: %s did not answer in 30 s; playing anyway", service)
    # --wait-for-subscribers: the first batches are not sent before the demodulator (or the
    # identifier) has subscribed; nothing counts a loss before a node's first message.
    cmd = ["rosbag", "play", "--clock", "--queue=%d" % QUEUE, "--rate=%g" % args.rate,
           "--delay=%g" % args.delay, "--wait-for-subscribers"]
    if args.loop == "true":
        cmd.append("--loop")
    cmd += [args.bag, "--topics"] + play
    cmd += ["%s:=/%s/%s" % (t, args.ns.strip("/"), t.split("/")[-1]) for t in play]
    proc = subprocess.Popen(cmd)
    try:
        code = proc.wait()
        rospy.loginfo("replay: the bag has been played (exit %d)", code)
        return code
    except KeyboardInterrupt:
        proc.terminate()
        proc.wait(10)
        return 0
    finally:
        rospy.set_param("/use_sim_time", False)
        rospy.loginfo("replay: /use_sim_time set back to false")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
