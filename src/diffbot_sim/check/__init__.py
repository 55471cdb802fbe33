"""Judging a robot: robot_check's report and session, and the drive check shared with the tests."""
