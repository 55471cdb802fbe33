"""ROS messages built from plain numbers: the one place that fills message classes."""
