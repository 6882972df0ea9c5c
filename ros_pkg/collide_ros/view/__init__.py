"""The live view: a ROS node serving one self-contained page that draws the sim and drives it
(docs/live_view.md). Modules: protocol (what a page may send), cdr_in (the node's bulk topics read
from their bytes), scene (state built from the node's topics), bridge (the ROS node), server (HTTP +
WebSocket), frames (the binary state frame), page.html (the page), foxglove_bridge
(--foxglove: the scene over the Foxglove WebSocket protocol) and foxglove_wire (its protobuf bytes)."""
