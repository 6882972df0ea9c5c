"""The live view: a ROS node serving one self-contained page that draws the sim and drives it
(docs/live_view.md). Modules: protocol (what a page may send), scene (state built from the node's
topics), bridge (the ROS node), server (HTTP + WebSocket), page.html (the page), foxglove_bridge
(--foxglove: the scene over the Foxglove WebSocket protocol) and foxglove_wire (its protobuf bytes)."""
