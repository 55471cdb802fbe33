"""Python package setup; run by catkin_python_setup(), never by hand.

The package list is read from the tree (every directory under src/ with an __init__.py), so a new subpackage
is installed without anyone remembering to list it here.
"""
import os

from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import find_packages, setup

SRC = os.path.join(os.path.dirname(os.path.abspath(__file__)), "src")

setup(**generate_distutils_setup(packages=find_packages(SRC), package_dir={"": "src"}))
