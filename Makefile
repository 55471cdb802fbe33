# The two commands a newcomer needs: `make run` and `make test`. Both set up first if needed.
SHELL := /bin/bash
ROOT := $(abspath $(dir $(lastword $(MAKEFILE_LIST))))
ENV := $(ROOT)/tools/rosenv.sh

.PHONY: setup run test test-slow unit bench clean

setup:
	@bash $(ROOT)/tools/setup.sh

run: setup
	@bash $(ENV) bash $(ROOT)/tools/run.sh

test: setup
	@bash $(ENV) python3 $(ROOT)/tools/run_tests.py

test-slow: setup
	@bash $(ENV) python3 $(ROOT)/tools/run_tests.py --slow

# Speed, latency, start-up and scale figures (tools/bench.py; ~6 min; writes bench-results/bench.json).
bench: setup
	@bash $(ENV) python3 $(ROOT)/tools/bench.py

unit: setup
	@bash $(ENV) python3 -m pytest -q $(ROOT)/tests/unit


clean:
	rm -rf $(ROOT)/catkin_ws/build $(ROOT)/catkin_ws/devel $(ROOT)/catkin_ws/src $(ROOT)/test-results $(ROOT)/bench-results
