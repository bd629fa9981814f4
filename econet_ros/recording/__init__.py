"""Recorded trials: rosbag2 bags written and read without ROS, and pictures of a trial."""
