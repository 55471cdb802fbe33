"""The sensors' models: ray sensors (lasers, rangers, clouds), cameras, noise. Pure: no rospy."""
