# The two commands a newcomer needs: `make run` and `make test`. Both set up first if needed.
SHELL := /bin/bash
ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
ENV := $(ROOT)/tools/rosenv.sh

.PHONY: setup run test test-slow test-nav unit bench pictures clean nav install moveit test-moveit

setup:
	@bash $(ROOT)/tools/setup.sh

run: setup
	@bash $(ENV) bash $(ROOT)/tools/run.sh

test: setup
	@bash $(ENV) python3 $(ROOT)/tools/run_tests.py

test-slow: setup
	@bash $(ENV) python3 $(ROOT)/tools/run_tests.py --slow

# Speed, latency, start-up and scale figures (tools/bench.py; ~6 min; writes bench-results/bench.json).
# ITEMS=fleet,arm runs only those items (`bash tools/rosenv.sh python3 tools/bench.py --help` lists them).
bench: setup
	@bash $(ENV) python3 $(ROOT)/tools/bench.py $(if $(ITEMS),--only $(ITEMS))

# The README's pictures (docs/rviz.png, docs/run.png, docs/pybullet.png) from a scripted run under Xvfb, and
# the rviz first-frame figure (tools/pictures.py; about 1 min).
pictures: setup
	@bash $(ENV) python3 $(ROOT)/tools/pictures.py

# The ROS 1 navigation stack and gmapping, which Debian 12 does not package, built into nav_ws/ (about 5 min the
# first time, seconds after). NAV_SOURCES=DIR takes the pinned tarballs from DIR instead of cloning.
nav: setup
	@NAV_SOURCES="$(NAV_SOURCES)" bash $(ROOT)/tools/nav.sh

# The navigation suites (tests/integration/nav_*.test: gmapping maps judged against the worlds, move_base goals
# judged by ground truth), at real time and in fast mode; after `make nav`. About 15 minutes.
test-nav: setup
	@bash $(ENV) python3 $(ROOT)/tools/run_tests.py --nav

# MoveIt 1 (noetic-devel 1.1.14) and the packages Debian 12 lacks, built into moveit_ws/ (about an hour on 2 cores
# the first time, seconds after; docs/moveit.md). MOVEIT_SOURCES=DIR[:DIR...] takes the pinned tarballs instead of
# cloning; MOVEIT_RVIZ=0 leaves out rviz's MotionPlanning plugin.
moveit: setup
	@MOVEIT_SOURCES="$(MOVEIT_SOURCES)" MOVEIT_RVIZ="$(MOVEIT_RVIZ)" bash $(ROOT)/tools/moveit.sh

# The MoveIt suites (tests/integration/moveit_*.test: plans executed in the simulator, judged by ground truth),
# at real time and in fast mode; after `make moveit`.
test-moveit: setup
	@bash $(ENV) python3 $(ROOT)/tools/run_tests.py --moveit

# An install space for users and images: DIR/setup.bash is all it needs, with this checkout gone (docs/install.md).
PREFIX = $(ROOT)/install
install: setup
	@bash $(ROOT)/tools/install.sh "$(PREFIX)"

unit: setup
	@bash $(ENV) python3 -m pytest -q $(ROOT)/tests/unit

# Static checks with the pinned tools of requirements-dev.txt, configured in pyproject.toml (rules and why):
# ruff on all the Python, mypy on src/diffbot_sim (its `files`; its cache in .mypy_cache/). A few seconds.
LINT_PATHS = src tools tests examples overlay setup.py
.PHONY: lint
lint: setup
	@cd $(ROOT) && .venv/bin/ruff check $(LINT_PATHS)
	@cd $(ROOT) && .venv/bin/mypy


clean:
	rm -rf $(ROOT)/catkin_ws/build $(ROOT)/catkin_ws/build_install $(ROOT)/catkin_ws/devel $(ROOT)/catkin_ws/src $(ROOT)/test-results $(ROOT)/bench-results
