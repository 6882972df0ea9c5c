"""The parts of the simulator node ``sim`` (collide_ros/node.py wires them into SimNode), one concern each:

guards        the lock shared by the stepping loop and the executor, throttled warnings, rejections,
              counted publishers and guarded command subscriptions and services
parameters    declaring the parameters, checking and applying changes
topology      the world (built from the scene and the parameters) and what depends on its body set
commands      the command topics: thrust, thrusters, spring, cmd_vel; echoes on applied/<topic>
forces        commands turned into each step's external forces (timeouts, the cmd_vel servo)
stepping      one physics step, split into parts when C undoes it, and what is due after it
publishing    poses, states, contacts, energy, /tf, markers, /clock
pose_frame    the bodies' poses and twists of one publish round, computed once and shared by the topics
publish_thread the thread that writes and sends the stepping loop's publish rounds beside the next step
scanners      laser scanners on bodies (the scene's ``scanners``): sensor_msgs/LaserScan from C ray casts
diagnostics   the /diagnostics status
services      ~/reset, ~/pause, ~/step, ~/kill
snapshots     ~/snapshot (the state a replay starts from) and ~/save_snapshot
spawning      ~/spawn and its checks (inside the static bodies' box, no overlap)
loop          the sleep-until stepping loop and the executor thread

Each is a mixin of SimNode: they share the node's attributes (the world, the parameters, the lock),
which tests and tools reach into; each file's class docstring names the state it owns.
"""
