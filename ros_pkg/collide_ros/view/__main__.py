"""python -m collide_ros.view: the live view (server.py)."""
import sys

from collide_ros.view.server import main

sys.exit(main())
