#!/usr/bin/env python3
"""A client of collision_world_node, as another program would drive it (rospy).

Spawns two touching cubes through the ~spawn service (and learns their ids),
reads their states on ~entity_states and their contacts on ~contacts, moves the
gaze to the image centre, then removes them through ~despawn. Prints what it
got. With --check it also verifies it (for a world without gravity and with
response off, as test/rostest/example_client.test runs it) and exits 1 on a
mismatch.

    rosrun sphere_tree_collision example_client.py [--world /collision_world] [--check]
"""
import argparse
import sys
import time

import rospy
from sphere_tree_collision.msg import ContactArray, EntityList, EntityStates, GazePoint, TickStats
from sphere_tree_collision.srv import DespawnEntity, Spawn, SpawnRequest

TIMEOUT = 60.0  # s: only guards against a node that is not there


def topic(world, name):
    """The node's topics and services are in its private namespace (--world)."""
    return world + "/" + name


class Client:
    def __init__(self, world):
        self.world = world
        for service in ("spawn", "despawn"):
            rospy.wait_for_service(topic(world, service), timeout=TIMEOUT)
        self.spawn_srv = rospy.ServiceProxy(topic(world, "spawn"), Spawn)
        self.despawn_srv = rospy.ServiceProxy(topic(world, "despawn"), DespawnEntity)
        self.gaze_pub = rospy.Publisher(topic(world, "gaze"), GazePoint, queue_size=10)
        self.states = None
        self.contacts = None
        self.stats = None
        self.entities = None
        rospy.Subscriber(topic(world, "entity_states"), EntityStates, self._keep("states"))
        rospy.Subscriber(topic(world, "contacts"), ContactArray, self._keep("contacts"))
        rospy.Subscriber(topic(world, "tick_stats"), TickStats, self._keep("stats"))
        rospy.Subscriber(topic(world, "entities"), EntityList, self._keep("entities"))

    def _keep(self, name):
        def callback(msg):
            setattr(self, name, msg)
        return callback

    def wait_for(self, what, condition):
        """Polls condition() until it holds; returns its value. The wall-clock
        bound only guards against a node that is not there."""
        end = time.monotonic() + TIMEOUT
        while not rospy.is_shutdown() and time.monotonic() < end:
            value = condition()
            if value:
                return value
            time.sleep(0.01)
        raise RuntimeError("timed out waiting for " + what)

    def spawn_cube(self, name, x):
        req = SpawnRequest()
        req.header.frame_id = ""  # the world frame; any tf frame works
        e = req.entity
        e.name, e.preset, e.resolution, e.voxel_size = name, "cube", 4, 0.05
        e.pose.position.x, e.pose.position.z = x, 1.0
        e.pose.orientation.w = 1.0
        e.density, e.restitution, e.friction = 1000.0, 0.3, 0.5
        return self.spawn_srv(req)

    def state_of(self, entity_id):
        if self.states is None:
            return None
        for i, eid in enumerate(self.states.ids):
            if eid == entity_id:
                return self.states.names[i], self.states.poses[i], self.states.twists[i]
        return None

    def look_at_image_centre(self):
        width = rospy.get_param(self.world + "/camera_width", 1280)
        height = rospy.get_param(self.world + "/camera_height", 720)
        gaze = GazePoint()
        gaze.header.stamp = rospy.Time.now()
        gaze.x, gaze.y = width / 2.0, height / 2.0
        self.gaze_pub.publish(gaze)


def run(world, check):
    """Returns a list of failures (empty when all is well, or without check)."""
    failures = []

    def expect(ok, what):
        if check and not ok:
            failures.append(what)
            rospy.logerr("example_client: " + what)

    c = Client(world)
    a = c.spawn_cube("client_a", 3.0)
    b = c.spawn_cube("client_b", 3.15)  # 0.2 m cubes 0.15 m apart: they overlap
    print("spawned client_a: success=%s id=%d frame=%s %s" % (a.success, a.id, a.frame_id, a.message))
    print("spawned client_b: success=%s id=%d frame=%s %s" % (b.success, b.id, b.frame_id, b.message))
    expect(a.success and b.success, "spawn failed: '%s' '%s'" % (a.message, b.message))
    expect(a.id != b.id, "both spawns got id %d" % a.id)
    expect(a.frame_id == "client_a" and b.frame_id == "client_b", "frames %s, %s" % (a.frame_id, b.frame_id))
    refused = c.spawn_cube("client_a", 5.0)  # the name is taken
    print("spawn of a taken name: success=%s message=%s" % (refused.success, refused.message))
    expect(not refused.success and refused.message.startswith("entity.name: "), "taken name not refused by field")

    listed = c.wait_for("~entities", lambda: c.entities and {a.id, b.id} <= {e.id for e in c.entities.entities})
    expect(bool(listed), "ids not in ~entities")
    c.wait_for("entity_states of both", lambda: c.state_of(a.id) and c.state_of(b.id))
    for eid in (a.id, b.id):
        name, pose, twist = c.state_of(eid)
        print("state of %s (id %d): position (%.3f, %.3f, %.3f), velocity (%.3f, %.3f, %.3f)" % (
            name, eid, pose.position.x, pose.position.y, pose.position.z,
            twist.linear.x, twist.linear.y, twist.linear.z))
    name_a, pose_a, _ = c.state_of(a.id)
    expect(name_a == "client_a", "state name %s" % name_a)
    expect(abs(pose_a.position.x - 3.0) < 1e-6 and abs(pose_a.position.z - 1.0) < 1e-6,
           "client_a is at (%g, %g), not where it was spawned" % (pose_a.position.x, pose_a.position.z))

    def contact_between():
        if c.contacts is None:
            return None
        for k in c.contacts.contacts:
            if {k.entity_a, k.entity_b} == {a.id, b.id}:
                return k
        return None
    k = c.wait_for("a contact between client_a and client_b", contact_between)
    print("contact %s - %s at (%.3f, %.3f, %.3f), depth %.4f m, level %d" % (
        k.name_a, k.name_b, k.point.x, k.point.y, k.point.z, k.depth, k.level))
    expect({k.name_a, k.name_b} == {"client_a", "client_b"}, "contact names %s, %s" % (k.name_a, k.name_b))

    def gaze_active():
        c.look_at_image_centre()
        return c.stats is not None and c.stats.gaze_active
    c.wait_for("the gaze to be active", gaze_active)
    print("gaze at the image centre: tick_stats.gaze_active = %s" % c.stats.gaze_active)

    for resp, name in ((c.despawn_srv(a.id, ""), "client_a"), (c.despawn_srv(0, "client_b"), "client_b")):
        print("despawned %s: success=%s %s" % (name, resp.success, resp.message))
        expect(resp.success, "despawn of %s failed: %s" % (name, resp.message))
    gone = c.despawn_srv(a.id, "")
    expect(not gone.success and gone.message.startswith("id: "), "second despawn not refused by id")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--world", default="/collision_world", help="namespace of the world node")
    parser.add_argument("--check", action="store_true", help="verify what came back; exit 1 on a mismatch")
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node("example_client", anonymous=True)
    failures = run(args.world, args.check)
    if failures:
        print("example_client: %d check(s) failed" % len(failures))
        return 1
    if args.check:
        print("example_client: all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
