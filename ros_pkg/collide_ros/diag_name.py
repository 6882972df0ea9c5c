"""The name of a sim node's status in /diagnostics, shared by the node that publishes it and by the
nodes and tests that read it (the live view's health line, collide_ros.testing)."""
from __future__ import annotations


def physics_status(node_name: str) -> str:
    """The status name for the sim node whose fully qualified name is ``node_name`` (``/sim``,
    ``/robot1/sim``): ``/robot1/sim: physics``, so sims side by side report apart."""
    return f"{node_name}: physics"


def sim_node_name(namespace: str, sim: str) -> str:
    """The fully qualified name of node ``sim`` in ``namespace`` (``/`` or ``/robot1``)."""
    return f"{namespace.rstrip('/')}/{sim}"
