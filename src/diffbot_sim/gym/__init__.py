"""Gymnasium (1.x) environments of diffbot_sim: a robot in a world, in-process, no ROS master, no rospy.

Importing this package registers, under the ``diffbot_sim/`` namespace:

* ``diffbot_sim/GoalRoom-v0``: the seed robot with its laser (urdf/diffbot_laser.urdf.xacro) reaches goals in
  worlds/room.world with TurtleBot3's five discrete actions;
* ``diffbot_sim/GoalRoomContinuous-v0``: the same with continuous (linear, angular) actions;
* ``diffbot_sim/Goal-v0``: any robot and world, ``gymnasium.make("diffbot_sim/Goal-v0", model=..., world=...)``.

Each is a :class:`diffbot_sim.gym.goal_env.GoalEnv` (keywords: :class:`~diffbot_sim.gym.goal_env.GoalConfig`),
truncated after MAX_EPISODE_STEPS steps (100 s of sim time at the default 0.2 s control period). In a process
that has not imported this package (``AsyncVectorEnv`` workers started by ``spawn``), name the module in the
id: ``gymnasium.make("diffbot_sim.gym:diffbot_sim/GoalRoom-v0")``. docs/gym.md has the details.
"""
from gymnasium.envs.registration import register, registry

from diffbot_sim.gym.goal_env import GoalConfig, GoalEnv, goal_config, turtlebot3_command

__all__ = ["ENV_IDS", "GoalConfig", "GoalEnv", "MAX_EPISODE_STEPS", "goal_config", "turtlebot3_command"]

#: Steps before TimeLimit truncates an episode (TurtleBot3's DQN agent: a 500-step "Time out!!").
MAX_EPISODE_STEPS = 500
ENTRY_POINT = "diffbot_sim.gym.goal_env:GoalEnv"
#: id -> the keywords it fixes.
ENV_IDS = {
    "diffbot_sim/GoalRoom-v0": {"world": "worlds/room.world", "actions": "discrete"},
    "diffbot_sim/GoalRoomContinuous-v0": {"world": "worlds/room.world", "actions": "continuous"},
    "diffbot_sim/Goal-v0": {},
}

for _id, _kwargs in ENV_IDS.items():
    if _id not in registry:
        register(id=_id, entry_point=ENTRY_POINT, max_episode_steps=MAX_EPISODE_STEPS, kwargs=dict(_kwargs))
