#!/usr/bin/env python3
"""Marker and tf publishing cost of collision_world_node (issue 5, items 6 and 7).

The node builds markers and tf only while someone listens. This measures what
listening costs the node: it starts a private roscore and the node on a scene
of N static rocks spread 1 m apart (so the tick itself is nearly free and the
node's CPU is its publishing), then reads the node's CPU time (/proc/PID/stat)
over a window with no subscriber, with a /markers subscriber, with a /tf
subscriber and with both. Subscribers take the raw bytes (rospy.AnyMsg), so
the Python side does not deserialise. Extra CPU per message = (CPU with the
subscriber - CPU without) / messages received.

Usage (after `source <build>/devel/setup.bash`):
  bench/ros_publish_cost.py [--entities 1000,5000] [--seconds 8] [--node PATH] [--markdown FILE]
"""
import argparse
import os
import socket
import subprocess
import sys
import tempfile
import time

import rospy
import rosgraph


def free_port():
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def find_node(explicit):
    if explicit:
        return explicit
    for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(":"):
        path = os.path.join(prefix, "lib", "sphere_tree_collision", "collision_world_node")
        if os.access(path, os.X_OK):
            return path
    sys.exit("collision_world_node not found: source <build>/devel/setup.bash or pass --node")


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    # fields[11], fields[12]: utime, stime (after the ")" of the command name)
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def scene_yaml(n):
    """n static rocks on a grid 1 m apart: no pair ever touches."""
    nx = 25
    ny = min(20, max(1, (n + nx - 1) // nx))
    nz = max(1, (n + nx * ny - 1) // (nx * ny))
    assert nx * ny * nz >= n
    lines = ["gravity: [0, 0, 0]", "entities:"]
    # repeat makes whole grids; the remainder (if any) is one more partial row set.
    full_layers = n // (nx * ny)
    rest = n - full_layers * nx * ny
    z = 0.5
    if full_layers:
        lines += [f"  - {{preset: rock, seed: 1, static: true, position: [0, 0, {z}],",
                  f"     repeat: {{count: [{nx}, {ny}, {full_layers}], spacing: [1.0, 1.0, 1.0]}}}}"]
        z += full_layers
    if rest:
        lines += [f"  - {{preset: rock, seed: 2, static: true, position: [0, 0, {z}],",
                  f"     repeat: {{count: [{rest}, 1, 1], spacing: [1.0, 0, 0]}}}}"]
    return "\n".join(lines) + "\n"


class Counter:
    def __init__(self, topic):
        self.messages = 0
        self.bytes = 0
        self.sub = rospy.Subscriber(topic, rospy.AnyMsg, self.on_message, queue_size=1, buff_size=1 << 28)

    def on_message(self, msg):
        self.messages += 1
        self.bytes += len(msg._buff)

    def close(self):
        self.sub.unregister()


def window(pid, topics, seconds):
    """Node CPU seconds per wall second, and per topic (messages, mean bytes)."""
    counters = {t: Counter(t) for t in topics}
    time.sleep(2.0)  # connect, and let the node see its subscribers
    for c in counters.values():
        c.messages = c.bytes = 0
    c0, t0 = cpu_seconds(pid), time.monotonic()
    time.sleep(seconds)
    c1, t1 = cpu_seconds(pid), time.monotonic()
    result = {t: (c.messages, c.bytes / max(1, c.messages)) for t, c in counters.items()}
    for c in counters.values():
        c.close()
    time.sleep(1.0)  # the node notices the subscriber is gone
    return (c1 - c0) / (t1 - t0), result, t1 - t0


def measure(node, n, seconds, rate, marker_rate):
    env = dict(os.environ)
    port = free_port()
    env["ROS_MASTER_URI"] = f"http://localhost:{port}"
    os.environ["ROS_MASTER_URI"] = env["ROS_MASTER_URI"]
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        f.write(scene_yaml(n))
        scene = f.name
    core = subprocess.Popen(["roscore", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    world = None
    try:
        master = rosgraph.Master("/publish_cost", master_uri=env["ROS_MASTER_URI"])
        for _ in range(300):
            try:
                master.getPid()
                break
            except Exception:
                time.sleep(0.1)
        world = subprocess.Popen([node, "__name:=collision_world", f"_scene:={scene}", f"_rate:={rate}",
                                  f"_marker_rate:={marker_rate}"], env=env, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
        rospy.init_node("publish_cost", anonymous=True, disable_signals=True)
        for _ in range(600):
            topics = dict(rospy.get_published_topics())
            if "/collision_world/markers" in topics and "/tf" in topics:
                break
            if world.poll() is not None:
                sys.exit(f"collision_world_node exited ({world.returncode}) with {n} entities")
            time.sleep(0.1)
        time.sleep(2.0)
        rows = {}
        for name, topics in [("none", []), ("markers", ["/collision_world/markers"]), ("tf", ["/tf"]),
                             ("both", ["/collision_world/markers", "/tf"])]:
            rows[name] = window(world.pid, topics, seconds)
        return rows
    finally:
        if world:
            world.terminate()
            world.wait()
        core.terminate()
        core.wait()
        os.unlink(scene)
        rospy.signal_shutdown("done")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--entities", default="1000,5000")
    ap.add_argument("--seconds", type=float, default=8.0)
    ap.add_argument("--rate", type=float, default=60.0)
    ap.add_argument("--marker-rate", type=float, default=10.0)
    ap.add_argument("--node")
    ap.add_argument("--markdown")
    args = ap.parse_args()
    node = find_node(args.node)
    counts = [int(x) for x in args.entities.split(",")]
    md = ("Node on N static rocks 1 m apart (tick nearly free), ~rate %g Hz, ~marker_rate %g Hz, default "
          "marker levels [1, 2] + voxels, %g s per window. CPU = node CPU seconds per wall second "
          "(1.0 = one core). Extra = (CPU - CPU with no subscriber) / messages received, in ms.\n\n"
          % (args.rate, args.marker_rate, args.seconds))
    md += ("| entities | subscribers | node CPU | markers msgs/s | marker msg size (MB) | tf msgs/s | "
           "tf msg size (MB) | extra ms per marker msg | extra ms per tf msg |\n"
           "|---|---|---|---|---|---|---|---|---|\n")
    for n in counts:
        # rospy can be initialised once per process: one child process per entity count.
        if len(counts) > 1:
            cmd = [sys.executable, __file__, "--entities", str(n), "--seconds", str(args.seconds),
                   "--rate", str(args.rate), "--marker-rate", str(args.marker_rate), "--node", node, "--rows-only"]
            out = subprocess.run(cmd, capture_output=True, text=True)
            sys.stderr.write(out.stderr)
            md += out.stdout
            continue
        md += rows_markdown(n, measure(node, n, args.seconds, args.rate, args.marker_rate))
    print(md)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(md)


def rows_markdown(n, rows):
    base = rows["none"][0]
    out = ""
    for name in ["none", "markers", "tf", "both"]:
        cpu, topics, wall = rows[name]
        m = topics.get("/collision_world/markers", (0, 0))
        t = topics.get("/tf", (0, 0))
        extra_m = (cpu - base) * wall / m[0] * 1e3 if name == "markers" and m[0] else None
        extra_t = (cpu - base) * wall / t[0] * 1e3 if name == "tf" and t[0] else None
        out += "| %d | %s | %.3f | %s | %s | %s | %s | %s | %s |\n" % (
            n, name, cpu,
            "%.1f" % (m[0] / wall) if m[0] else "-", "%.2f" % (m[1] / 1e6) if m[0] else "-",
            "%.1f" % (t[0] / wall) if t[0] else "-", "%.3f" % (t[1] / 1e6) if t[0] else "-",
            "%.2f" % extra_m if extra_m is not None else "-", "%.3f" % extra_t if extra_t is not None else "-")
    return out


if __name__ == "__main__":
    if "--rows-only" in sys.argv:
        sys.argv.remove("--rows-only")
        ap = argparse.ArgumentParser()
        ap.add_argument("--entities", type=int)
        ap.add_argument("--seconds", type=float)
        ap.add_argument("--rate", type=float)
        ap.add_argument("--marker-rate", type=float)
        ap.add_argument("--node")
        a = ap.parse_args()
        print(rows_markdown(a.entities, measure(a.node, a.entities, a.seconds, a.rate, a.marker_rate)), end="")
    else:
        main()
