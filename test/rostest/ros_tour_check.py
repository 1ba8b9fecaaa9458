#!/usr/bin/env python3
"""The README's five-minute ROS tour as a rostest: the commands below are run
exactly as the README prints them (through a shell, as a user types them),
against the node world.launch starts. Each is judged by what it answers or
prints and by the node's states (the spawned rock listed, the gaze active),
never by time: the waits are liveness bounds only."""
import subprocess
import unittest

import rospy
import rostest
from sphere_tree_collision.msg import EntityList, EntityStates, TickStats

# The tour, as the README prints it (after `roslaunch sphere_tree_collision world.launch`).
# The gaze needs -s (--substitute-keywords): without it `rostopic pub -r` sends
# the first message's `now` again and again, and the node refuses every gaze
# message after ~gaze_timeout (0.5 s) as stale.
SPAWN = """rosservice call /collision_world/spawn "{entity: {name: 'r1', preset: 'rock', pose: {position: {z: 2}}}}\""""
GAZE = """rostopic pub -s -r 10 /collision_world/gaze sphere_tree_collision/GazePoint "{header: {stamp: now}, x: 640, y: 360}\""""
ECHO_STATS = "rostopic echo -n 1 /collision_world/tick_stats"
ECHO_CONTACTS = "rostopic echo -n 1 /collision_world/contacts"

LIVENESS_S = 60.0  # a bound for a loaded machine, not a measure


def run(command):
    """Runs `command` as typed into a shell; returns (exit code, stdout + stderr)."""
    done = subprocess.run(["bash", "-c", command], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          timeout=LIVENESS_S, universal_newlines=True)
    return done.returncode, done.stdout


class Latest:
    """The last message of a topic."""

    def __init__(self, topic, msg_type):
        self.msg = None
        self.sub = rospy.Subscriber(topic, msg_type, self._on)

    def _on(self, msg):
        self.msg = msg

    def wait_for(self, holds):
        deadline = rospy.Time.now() + rospy.Duration(LIVENESS_S)
        while not rospy.is_shutdown() and rospy.Time.now() < deadline:
            if self.msg is not None and holds(self.msg):
                return True
            rospy.sleep(0.05)
        return False


class RosTour(unittest.TestCase):
    def test_the_tour_commands_do_what_the_readme_says(self):
        rospy.wait_for_service("/collision_world/spawn", timeout=LIVENESS_S)
        stats = Latest("/collision_world/tick_stats", TickStats)
        entities = Latest("/collision_world/entities", EntityList)
        states = Latest("/collision_world/entity_states", EntityStates)

        # (1) The shortest spawn: density, resolution, voxel size and orientation take their defaults.
        code, out = run(SPAWN)
        self.assertEqual(code, 0, out)
        self.assertIn("success: True", out)
        self.assertIn('frame_id: "r1"', out)
        self.assertTrue(entities.wait_for(lambda m: any(e.name == "r1" for e in m.entities)),
                        "r1 is not in ~entities")
        self.assertTrue(states.wait_for(lambda m: "r1" in m.names), "r1 is not in ~entity_states")

        # (2) The gaze, sent in the background, makes tick_stats report it active.
        gaze = subprocess.Popen(["bash", "-c", "exec " + GAZE], stdout=subprocess.DEVNULL,
                                stderr=subprocess.STDOUT)
        try:
            self.assertTrue(stats.wait_for(lambda m: m.gaze_active), "tick_stats never reports the gaze active")
            # (3) One message each, printed as YAML.
            code, out = run(ECHO_STATS)
            self.assertEqual(code, 0, out)
            self.assertIn("tick: ", out)
            self.assertIn("gaze_active: ", out)  # its value is judged on the subscription, not on one sample
            self.assertIn("entities: 7", out)  # the default scene's six and r1
            code, out = run(ECHO_CONTACTS)
            self.assertEqual(code, 0, out)
            self.assertIn("frame_id: \"world\"", out)
            self.assertIn("contacts: ", out)
            # Still active at a tick after the echoes (each a new process, longer than
            # ~gaze_timeout): the stamps are fresh in every message, not only the first
            # (without -s, rostopic pub -r would send its first `now` again and again).
            tick = stats.msg.tick
            self.assertTrue(stats.wait_for(lambda m: m.tick > tick and m.gaze_active),
                            "the gaze went stale: rejected_gaze %d, last rejection '%s'"
                            % (stats.msg.rejected_gaze, stats.msg.last_rejection))
            self.assertIsNone(gaze.poll(), "rostopic pub stopped")
        finally:
            gaze.terminate()
            gaze.wait()


if __name__ == "__main__":
    rospy.init_node("ros_tour_check")
    rostest.rosrun("sphere_tree_collision", "ros_tour", RosTour)
