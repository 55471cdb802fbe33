"""The bench kit: what every ``make bench`` item is made of (tools/bench.py runs the items of tools/bench_items/).

- ``common``: where things are (the repository, bench-results/), the seed model, the step, the circle robots drive;
- ``launching``: a ``roslaunch -p PORT`` with its own master, subscriber processes, start-up to first ``/odom``;
- ``probes``: the ROS-side measurements every item uses (run as ``bench.py --probe KIND`` in a child process);
- ``bare``: the bare-PyBullet references an item pairs the simulator with (models loaded as bullet_sim loads
  them, a robot that fell over refused);
- ``stats``: percentiles, the median trial, the largest robot count that keeps real time;
- ``report``: an item's record, the results file and the printed table.

The kit imports none of the items and nothing of tools/bench.py: items import the kit, bench.py imports both.
"""
