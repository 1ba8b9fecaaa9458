#!/usr/bin/env python3
"""Runs scripts/example_client.py's run() with its checks as a rostest: ids,
frames, states, contact names, gaze and despawn answers must be as asked."""
import os
import sys
import unittest

import rospy
import rostest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import example_client  # noqa: E402


class ExampleClient(unittest.TestCase):
    def test_client_gets_back_what_it_asked_for(self):
        failures = example_client.run("/collision_world", check=True)
        self.assertEqual(failures, [])


if __name__ == "__main__":
    rospy.init_node("example_client_check")
    rostest.rosrun("sphere_tree_collision", "example_client", ExampleClient)
