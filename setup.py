"""Python package setup; run by catkin_python_setup(), never by hand."""
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["diffbot_sim", "diffbot_sim.nodes", "diffbot_sim.plugins"], package_dir={"": "src"}))
