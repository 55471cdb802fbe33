"""``batch``: many rostest scenarios run in parallel, on this machine or a Ray cluster.

``scenarios`` reads and expands the scenario file (pure), ``run`` runs one scenario run as processes of this
machine (its own master, log folders and clean-up), ``results`` records and reports runs, ``executors`` spreads
runs over local processes or Ray tasks. No rospy here: a run's ROS processes are children, never this process.
"""
