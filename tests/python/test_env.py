"""The project environment (scripts/setup + scripts/env.sh + conftest) is what the code relies on."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

import ros_domain

TF_TYPE = "tf2_msgs/msg/TFMessage"


def jazzy_hash(type_name: str) -> str:
    from rosbags.typesys import Stores, get_typestore

    return str(get_typestore(Stores.ROS2_JAZZY).hash_rihs01(type_name))


def test_discovery_is_localhost_and_domain_is_locked(ros_domain_id: int) -> None:
    assert os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "LOCALHOST"
    assert "ROS_LOCALHOST_ONLY" not in os.environ
    assert ros_domain.MIN_ID <= ros_domain_id <= ros_domain.MAX_ID
    assert ros_domain_id not in ros_domain.HAND_RUN_IDS
    # The port lock is really held (by this process): nobody else can take this id now.
    assert ros_domain.try_lock(ros_domain_id) is None


def test_allocator_gives_distinct_ids_and_frees_them() -> None:
    a = ros_domain.acquire()
    b = ros_domain.acquire()
    try:
        assert a.domain_id != b.domain_id
        assert ros_domain.is_locked(a.domain_id) and ros_domain.is_locked(b.domain_id)
    finally:
        a.release()
        b.release()
    assert not ros_domain.is_locked(a.domain_id)


def test_subprocesses_inherit_the_ros_environment(ros_domain_id: int) -> None:
    out = subprocess.run(
        [sys.executable, "-c",
         "import os; print(os.environ['ROS_DOMAIN_ID'], os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'])"],
        check=True, capture_output=True, text=True).stdout.split()
    assert out == [str(ros_domain_id), "LOCALHOST"]


def test_message_packages_match_the_contract() -> None:
    from libcollide_msgs.msg import BodyStates, Contact, Contacts, Energy, SpringCommand, ThrusterCommand
    from libcollide_msgs.srv import Kill, Spawn, Step

    assert BodyStates.get_fields_and_field_types() == {
        "header": "std_msgs/Header", "names": "sequence<string>",
        "poses": "sequence<geometry_msgs/Pose>", "twists": "sequence<geometry_msgs/Twist>"}
    assert (Contact.COLLISION, Contact.RESTING) == (0, 1)
    assert list(Contact.get_fields_and_field_types()) == [
        "body_a", "body_b", "point", "normal", "gap", "normal_velocity", "impulse",
        "tangent_impulse", "force", "kind"]
    assert Contacts.get_fields_and_field_types()["contacts"] == "sequence<libcollide_msgs/Contact>"
    assert list(Energy.get_fields_and_field_types()) == [
        "header", "translational", "rotational", "gravitational", "spring", "total",
        "linear_momentum", "angular_momentum"]
    assert ThrusterCommand.get_fields_and_field_types()["firing"] == "sequence<boolean>"
    assert list(SpringCommand.get_fields_and_field_types()) == [
        "header", "name", "body", "body_point", "target", "stiffness", "damping", "rest_length",
        "release"]
    assert Step.Response.get_fields_and_field_types()["sim_time"] == "builtin_interfaces/Time"
    assert Spawn.Request.get_fields_and_field_types()["vertices"] == "sequence<double>"
    assert list(Kill.Response.get_fields_and_field_types()) == ["success", "message"]


def test_rebuilt_tfmessage_has_jazzys_type_hash() -> None:
    """rclpy reports our TFMessage's RIHS01 hash on the graph; it must be Jazzy's exact hash."""
    import rclpy
    from rclpy.context import Context
    from tf2_msgs.msg import TFMessage

    context = Context()
    rclpy.init(context=context)
    try:
        node = rclpy.create_node("test_env_tf_hash", context=context)
        node.create_publisher(TFMessage, "test_env_tf", 1)
        infos = node.get_publishers_info_by_topic("test_env_tf")
        assert len(infos) == 1
        assert infos[0].topic_type == TF_TYPE
        assert str(infos[0].topic_type_hash) == jazzy_hash(TF_TYPE)
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)


PUBLISHER = textwrap.dedent("""
    import sys, time, rclpy
    from libcollide_msgs.msg import Contact, Contacts
    rclpy.init()
    node = rclpy.create_node("test_env_talker")
    pub = node.create_publisher(Contacts, "test_env_contacts", 10)
    msg = Contacts(contacts=[Contact(body_a="block1", body_b="wall_left", impulse=2.5,
                                     kind=Contact.RESTING)])
    for _ in range(int(sys.argv[1])):
        pub.publish(msg)
        time.sleep(0.05)
    rclpy.shutdown()
""")


def test_custom_message_crosses_processes_on_our_domain() -> None:
    """A subprocess (inheriting ROS_DOMAIN_ID + LOCALHOST) publishes Contacts; we receive it intact."""
    import rclpy
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from libcollide_msgs.msg import Contact, Contacts

    context = Context()
    rclpy.init(context=context)
    received: list[Contacts] = []
    # 1200 x 50 ms: the publisher gives up after 60 s. This bounds a broken setup (no delivery)
    # instead of hanging; discovery on loopback normally takes well under a second.
    talker = subprocess.Popen([sys.executable, "-c", PUBLISHER, "1200"])
    try:
        node = rclpy.create_node("test_env_listener", context=context)
        node.create_subscription(Contacts, "test_env_contacts", received.append, 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)
        while not received and talker.poll() is None:
            executor.spin_once(timeout_sec=0.1)
        assert received, "no Contacts message arrived from the subprocess"
        contact = received[0].contacts[0]
        assert (contact.body_a, contact.body_b, contact.kind) == ("block1", "wall_left", Contact.RESTING)
        assert contact.impulse == 2.5  # exact: a float64 copied through CDR, no arithmetic
        executor.shutdown()
        node.destroy_node()
    finally:
        talker.terminate()
        talker.wait()
        rclpy.shutdown(context=context)


@pytest.mark.parametrize("name", ["geometry_msgs.msg", "std_srvs.srv", "visualization_msgs.msg",
                                  "rosgraph_msgs.msg", "diagnostic_msgs.msg"])
def test_common_interfaces_import(name: str) -> None:
    module = __import__(name, fromlist=["_"])
    assert module.__name__ == name

