"""Gazebo plugins, one module each, found by filename through :mod:`diffbot_sim.plugins.registry` (rospy).

Like Gazebo, which loads a plugin class by its filename, gives it its SDF element and calls it on every
world update: each module here owns its tags (both dialects where Gazebo had two), its defaults, its ROS
endpoints and its per-step work. The simulator's loop asks every plugin of every robot what is due and
knows none by name. :mod:`diffbot_sim.description.plugin_tags` (pure) reads the plugin elements of a model.
"""
