"""What every bench item shares: where things are, the seed robot, the step, the circle robots drive."""
import os

#: tools/
TOOLS = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: the repository
ROOT = os.path.dirname(TOOLS)
#: where the bench writes its logs, generated models and bench.json
RESULTS = os.path.join(ROOT, "bench-results")
#: the script whose ``--probe KIND`` runs a probe in a child process (tools/bench.py)
BENCH = os.path.join(TOOLS, "bench.py")
#: the seed robot
MODEL = os.path.join(ROOT, "urdf", "diffbot.urdf.xacro")
#: the robot fixtures of the test suites
ROBOTS = os.path.join(ROOT, "tests", "data", "robots")
#: [s] the simulator's default physics step, and every bare-PyBullet reference's
STEP = 1.0 / 240.0
#: the seed robot's standard topics
TOPICS = ["/clock", "/odom", "/joint_states", "/tf"]
#: (m/s, rad/s): the circle the RTF probe drives every robot in (wheels, casters and contacts all busy)
CIRCLE = (0.2, 0.5)
