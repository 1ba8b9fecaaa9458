#!/usr/bin/env python3
"""rviz's frame rate in the demo under software rendering (issue 50, item 6).

Each trial runs the demo as a user does, on a private master and a private
1920x1080 Xvfb screen: `roslaunch sphere_tree_collision demo.launch
rviz:=false` with a variant's arguments, then rviz full-screen with the
variant's config (rviz/demo.rviz with some marker namespaces switched) and
flags, LIBGL_ALWAYS_SOFTWARE=1. rviz_fps_hook.c (LD_PRELOAD) logs every
frame rviz presents; the trial's figure is frames / seconds over a window of
rviz's run ([--warmup, --warmup + --window] s: the rocks keep dropping, so
the scene is full). The machine is shared: variants alternate, round after
round, and the table gives each one's median and range. A screenshot of each
variant's first trial (rviz_fps_<variant>.png in --shots) shows what it draws.

Usage (after `source <build>/devel/setup.bash`):
  python3 bench/rviz_fps.py [--rounds 4] [--variants demo,aa,...] [--markdown FILE] [--shots DIR] [--smoke]
"""
import argparse
import os
import re
import shutil
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# name: (what it draws, demo.launch arguments, rviz namespaces switched, rviz flags)
VARIANTS = {
    "before": ("rocks as voxels, walls as voxels, anti-aliased (before issue 50)",
               ["marker_levels:=[2]", "static_voxel_markers:=true", "marker_keyframe_period:=2.0"],
               {"voxels": True, "tree_level_1": False, "tree_level_2": False}, []),
    "aa": ("rocks as tree level 1, walls as boxes, anti-aliased (rviz's default)", [], {}, []),
    "demo": ("the demo's: rocks as tree level 1, walls as boxes, no anti-aliasing", [], {},
             ["--disable-anti-aliasing"]),
    "level2": ("the same, rocks as tree level 2", ["marker_levels:=[2]"], {"tree_level_1": False, "tree_level_2": True},
               ["--disable-anti-aliasing"]),
    "walls_hidden": ("the same, walls hidden", [], {"static_boxes": False}, ["--disable-anti-aliasing"]),
    "marker_rate5": ("the same, 5 marker arrays a second instead of 10", ["marker_rate:=5"], {},
                     ["--disable-anti-aliasing"]),
}


def cpu_seconds(pid):
    """CPU time of a process, all its threads (llvmpipe's rasterisers too)."""
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def free_port():
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def variant_config(base, namespaces, path):
    """demo.rviz with the Markers display's namespaces set as given (added when absent)."""
    with open(base) as f:
        lines = f.read().split("\n")
    start = next(i for i, l in enumerate(lines) if l.strip() == "Name: Markers")
    ns_at = next(i for i in range(start, len(lines)) if lines[i].strip() == "Namespaces:")
    indent = None
    end = ns_at + 1
    while end < len(lines) and re.match(r"^\s+\w+: (true|false)$", lines[end]):
        indent = indent or lines[end][: len(lines[end]) - len(lines[end].lstrip())]
        end += 1
    block = {l.split(":")[0].strip(): l.strip().endswith("true") for l in lines[ns_at + 1:end]}
    block.update(namespaces)
    indent = indent or " " * 8
    lines[ns_at + 1:end] = [f"{indent}{k}: {'true' if v else 'false'}" for k, v in block.items()]
    with open(path, "w") as f:
        f.write("\n".join(lines))


def stop(proc, sig=signal.SIGTERM):
    if proc is None or proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, sig)
        proc.wait(timeout=15)
    except (subprocess.TimeoutExpired, ProcessLookupError):
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()


def start_xvfb(tmp):
    """Xvfb on the first free display from :90 (-noreset: it outlives rviz's restarts)."""
    number = next(n for n in range(90, 200) if not os.path.exists(f"/tmp/.X{n}-lock"))
    proc = subprocess.Popen(["Xvfb", f":{number}", "-screen", "0", "1920x1080x24", "-nolisten", "tcp", "-noreset"],
                            stdout=open(os.path.join(tmp, "xvfb.log"), "w"), stderr=subprocess.STDOUT,
                            start_new_session=True)
    for _ in range(150):
        if os.path.exists(f"/tmp/.X11-unix/X{number}"):
            return proc, f":{number}"
        time.sleep(0.1)
    stop(proc)
    sys.exit(f"Xvfb did not start on :{number} (log in {tmp})")


def trial(name, args, tmp, display, hook, shot):
    _, launch_args, namespaces, flags = VARIANTS[name]
    config = os.path.join(tmp, f"{name}.rviz")
    variant_config(os.path.join(ROOT, "rviz", "demo.rviz"), namespaces, config)
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}", ROS_HOME=tmp)
    launch = subprocess.Popen(["roslaunch", "-p", str(port), "sphere_tree_collision", "demo.launch", "rviz:=false"]
                              + launch_args, env=env, stdout=open(os.path.join(tmp, "launch.log"), "w"),
                              stderr=subprocess.STDOUT, start_new_session=True)
    rviz = None
    log = os.path.join(tmp, f"{name}.fps")
    try:
        time.sleep(args.startup)
        if os.path.exists(log):
            os.remove(log)
        rviz_env = dict(env, DISPLAY=display, LIBGL_ALWAYS_SOFTWARE="1", LD_PRELOAD=hook, STC_FPS_LOG=log)
        rviz = subprocess.Popen(["rviz", "-d", config, "--fullscreen"] + flags, env=rviz_env,
                                stdout=open(os.path.join(tmp, "rviz.log"), "w"), stderr=subprocess.STDOUT,
                                start_new_session=True)
        t0 = time.monotonic()
        time.sleep(args.warmup)
        cpu0 = cpu_seconds(rviz.pid)
        time.sleep(args.window)
        cpu1 = cpu_seconds(rviz.pid)
        time.sleep(1.0)
        if rviz.poll() is not None or launch.poll() is not None:
            sys.exit(f"{name}: rviz or the demo exited (logs in {tmp})")
        if shot:
            subprocess.run(["import", "-display", display, "-window", "root", shot], check=False)
    finally:
        stop(rviz)
        stop(launch, signal.SIGINT)
    frames = []
    with open(log) as f:
        for line in f:
            t, n = line.split()
            frames.append(float(t) - t0)
    lo, hi = args.warmup, args.warmup + args.window
    n = sum(1 for t in frames if lo <= t < hi)
    return n / args.window, 1000.0 * (cpu1 - cpu0) / max(n, 1)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--variants", default="aa,demo,level2,walls_hidden,marker_rate5",
                   help="comma-separated, of: " + ", ".join(VARIANTS))
    p.add_argument("--rounds", type=int, default=4)
    p.add_argument("--startup", type=float, default=5.0, help="s from roslaunch to rviz")
    p.add_argument("--warmup", type=float, default=30.0, help="s of rviz's run before the window")
    p.add_argument("--window", type=float, default=15.0, help="s counted")
    p.add_argument("--markdown", help="write the table here too")
    p.add_argument("--shots", help="directory for a screenshot per variant")
    p.add_argument("--smoke", action="store_true", help="one short round of two variants (checks the bench runs)")
    args = p.parse_args()
    if args.smoke:
        args.rounds, args.startup, args.warmup, args.window = 1, 3.0, 10.0, 5.0
        args.variants = "aa,demo"
    names = args.variants.split(",")
    for n in names:
        if n not in VARIANTS:
            sys.exit(f"--variants: unknown variant {n!r} (known: {', '.join(VARIANTS)})")
    for exe in ("Xvfb", "rviz", "roslaunch", "cc", "import"):
        if not shutil.which(exe):
            sys.exit(f"{exe} not found on PATH")
    tmp = tempfile.mkdtemp(prefix="stc_rviz_fps_")
    hook = os.path.join(tmp, "rviz_fps_hook.so")
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", hook, os.path.join(HERE, "rviz_fps_hook.c"), "-ldl"],
                   check=True)
    xvfb, display = start_xvfb(tmp)
    fps = {n: [] for n in names}
    cpu_ms = {n: [] for n in names}
    try:
        for r in range(args.rounds):
            order = names if r % 2 == 0 else names[::-1]  # alternate: no variant always first or last
            for n in order:
                shot = os.path.join(args.shots, f"rviz_fps_{n}.png") if args.shots and r == 0 else None
                load = os.getloadavg()[0]
                f, ms = trial(n, args, tmp, display, hook, shot)
                fps[n].append(f)
                cpu_ms[n].append(ms)
                print(f"round {r + 1}: {n}: {f:.1f} fps, {ms:.0f} ms of rviz CPU a frame (load {load:.1f})", flush=True)
    finally:
        stop(xvfb)
    rows = ["| displays | variant | fps, median | range | rviz CPU ms a frame, median |", "|---|---|---:|---:|---:|"]
    for n in names:
        rows.append(f"| {VARIANTS[n][0]} | `{n}` | **{statistics.median(fps[n]):.1f}** | "
                    f"{min(fps[n]):.1f}-{max(fps[n]):.1f} | {statistics.median(cpu_ms[n]):.0f} |")
    table = "\n".join(rows)
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(table + "\n")
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
