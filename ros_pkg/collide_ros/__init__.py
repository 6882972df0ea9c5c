"""collide_ros: the ROS 2 node around libcollide (node.py) and its tools."""
