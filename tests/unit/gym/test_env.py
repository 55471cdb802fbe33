"""The Gymnasium environments (diffbot_sim.gym), judged by the body: Gymnasium's own checker, determinism of
seeded episodes to 1e-9 m of ground truth, resets that restore the world exactly however many came before,
one action held for exactly one control period of sim time, goals and collisions judged by the robot's true
pose and contacts in worlds/room.world, TurtleBot3's discrete actions, and vector environments of two."""
import math
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import diffbot_sim.gym as dgym
from diffbot_sim.errors import ConfigError

ROOM = "diffbot_sim/GoalRoom-v0"
# In worlds/room.world: the row y = 1.0 is free from wall to wall (x in [-3, 3]); the pillar, ring and box
# all lie at y <= 0.15.
OPEN_ROW = 1.0


@pytest.fixture(scope="module")
def env():
    made = gymnasium.make(ROOM)
    yield made
    made.close()


def rollout(env, seed, actions):
    """Observations and ground-truth poses of one seeded episode driven by ``actions`` (stops at its end)."""
    obs, info = env.reset(seed=seed)
    observations, poses = [obs], [(info["x"], info["y"], info["yaw"])]
    for action in actions:
        obs, _, terminated, truncated, info = env.step(action)
        observations.append(obs)
        poses.append((info["x"], info["y"], info["yaw"]))
        if terminated or truncated:
            break
    return np.array(observations), np.array(poses)


def test_registered_ids_and_spaces(env):
    for env_id in ("diffbot_sim/GoalRoom-v0", "diffbot_sim/GoalRoomContinuous-v0", "diffbot_sim/Goal-v0"):
        assert env_id in gymnasium.registry
        assert gymnasium.registry[env_id].max_episode_steps == dgym.MAX_EPISODE_STEPS
    raw = env.unwrapped
    assert raw.action_space == gymnasium.spaces.Discrete(5)
    space = raw.observation_space
    assert space.shape == (24 + 4,) and space.dtype == np.float32
    # the seed laser's own range (urdf/diffbot_laser.urdf.xacro: 0.12 to 8 m), then twist and polar goal
    assert space.low[0] == pytest.approx(0.12) and space.high[23] == pytest.approx(8.0)
    assert space.low[27] == pytest.approx(-math.pi) and space.high[27] == pytest.approx(math.pi)


def test_gymnasium_checker_passes_without_warnings(env):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env.unwrapped)
    assert [str(w.message) for w in caught] == []


def test_same_seed_same_trajectory_in_another_env_and_after_other_episodes(env):
    actions = [int(a) for a in np.random.default_rng(5).integers(5, size=25)]
    first_obs, first_poses = rollout(env, 3, actions)
    for seed in range(20):  # other episodes in between, each cut short
        rollout(env, 100 + seed, actions[:3])
    again_obs, again_poses = rollout(env, 3, actions)
    other = gymnasium.make(ROOM)
    try:
        other_obs, other_poses = rollout(other, 3, actions)
    finally:
        other.close()
    assert len(first_poses) > 10 and np.ptp(first_poses[:, 0]) + np.ptp(first_poses[:, 1]) > 0.1  # it moved
    for obs, poses in ((again_obs, again_poses), (other_obs, other_poses)):
        assert np.abs(poses - first_poses).max() <= 1e-9
        assert np.array_equal(obs, first_obs)
    different_obs, _ = rollout(env, 4, actions)
    assert not np.array_equal(different_obs[0], first_obs[0])


def test_reset_restores_the_world_without_drift(env):
    scene = env.unwrapped.scene
    box = next(uid for uid, body in scene.world.world_bodies if body.model == "pushable_box")
    box_body = next(body for uid, body in scene.world.world_bodies if uid == box)
    start = (1.4, 0.0, 0.0)  # facing the pushable box (its west face at x = 1.85)
    env.reset(seed=1, options={"start": start, "goal": (-2.0, OPEN_ROW)})
    box_before = scene.world.body_pose(box, box_body.inertial_pose)
    for _ in range(12):  # drive into the box: the episode ends on the contact
        _, _, terminated, _, info = env.step(2)
        if terminated:
            break
    assert info["outcome"] == "collision"
    for seed in range(60):
        env.reset(seed=seed)
        env.step(seed % 5)
    obs, info = env.reset(seed=1, options={"start": start, "goal": (-2.0, OPEN_ROW)})
    assert (info["x"], info["y"]) == pytest.approx(start[:2], abs=1e-6) and info["yaw"] == pytest.approx(0.0, abs=1e-6)
    assert scene.world.body_pose(box, box_body.inertial_pose)[0] == pytest.approx(box_before[0], abs=1e-9)
    assert scene.velocity() == pytest.approx((0.0, 0.0), abs=1e-9) and scene.time == 0.0
    again, _ = env.reset(seed=1, options={"start": start, "goal": (-2.0, OPEN_ROW)})
    assert np.array_equal(obs, again)
    env.step(0)  # turning: the wheel motors now have targets, which a snapshot does not hold (bullet3 #4364)
    env.reset(seed=1, options={"start": start, "goal": (-2.0, OPEN_ROW)})
    for _ in range(48):  # bare physics, no command: the reset motors hold the robot still
        scene.world.step()
    assert scene.velocity() == pytest.approx((0.0, 0.0), abs=1e-3)
    assert scene.pose2d() == pytest.approx(start, abs=1e-3)


def test_an_action_is_held_for_exactly_one_control_period(env):
    raw = env.unwrapped
    scene = raw.scene
    env.reset(seed=2, options={"start": (-2.0, OPEN_ROW, 0.0), "goal": (2.0, OPEN_ROW)})
    commands = []
    step = scene.world.step

    def counted_step():
        commands.append((scene.drive.core.linear, scene.drive.core.angular))
        step()

    scene.world.step = counted_step
    try:
        for k, action in enumerate((1, 3, 2), start=1):
            before = len(commands)
            _, _, terminated, _, info = env.step(action)
            assert not terminated
            assert len(commands) - before == 48  # 0.2 s of 1/240 s steps
            assert set(commands[before:]) == {dgym.turtlebot3_command(action)}
            assert info["sim_time"] == pytest.approx(0.2 * k, abs=1e-12)
    finally:
        del scene.world.step
    _, _, _, _, info = env.step(1)  # turning left at 0.75 rad/s: the heading follows within the period
    assert scene.velocity()[1] == pytest.approx(0.75, abs=0.08)


def test_goal_reached_driving_straight_at_a_goal_ahead(env):
    start, goal = (-2.0, OPEN_ROW, 0.0), (-0.8, OPEN_ROW)
    obs, info = env.reset(seed=0, options={"start": start, "goal": goal})
    assert obs[-2] == pytest.approx(1.2, abs=1e-5) and obs[-1] == pytest.approx(0.0, abs=1e-5)
    steps = None  # the period the goal was reached in
    for period in range(1, 60):
        previous = info["distance"]
        _, reward, terminated, truncated, info = env.step(2)
        if terminated:
            steps = period
            break
        assert reward == pytest.approx(10.0 * (previous - info["distance"]) - 0.01)
    assert info["outcome"] == "goal" and info["is_success"] and not truncated
    assert math.hypot(info["x"] - goal[0], info["y"] - goal[1]) <= 0.2  # the body is there
    assert abs(info["y"] - OPEN_ROW) < 0.02  # straight
    # 1.0 m at 0.15 m/s is 33.3 periods of 0.2 s (plus the 1.8 m/s^2 ramp)
    assert steps is not None and 30 <= steps <= 36
    assert reward == pytest.approx(10.0 * (previous - info["distance"]) - 0.01 + 10.0)


def test_collision_ends_the_episode_at_the_wall(env):
    scene = env.unwrapped.scene
    env.reset(seed=0, options={"start": (2.0, OPEN_ROW, 0.0), "goal": (-2.0, OPEN_ROW)})
    for _ in range(60):
        _, reward, terminated, truncated, info = env.step(2)
        if terminated:
            break
    assert info["outcome"] == "collision" and not info["is_success"] and not truncated
    assert reward < -9.0
    east_wall = next(uid for uid, body in scene.world.world_bodies if body.name == "walls::east")
    assert scene.world.touching(scene.robot.body, scene.ground) == {east_wall}
    assert 2.80 < info["x"] < 2.95  # the wall's face is at x = 3.0; the robot is ~0.12 m long in front
    assert info["sim_time"] == pytest.approx((info["x"] - 2.0) / 0.15, abs=0.25)  # driven at 0.15 m/s


def test_discrete_actions_are_turtlebot3s(env):
    expected = [(0.15, 1.5), (0.15, 0.75), (0.15, 0.0), (0.15, -0.75), (0.15, -1.5)]
    assert [dgym.turtlebot3_command(a) for a in range(5)] == expected
    assert [env.unwrapped.command_for(np.int64(a)) for a in range(5)] == expected
    with pytest.raises(ValueError):
        env.unwrapped.command_for(5)


def test_continuous_actions_and_bad_keywords():
    env = gymnasium.make("diffbot_sim/GoalRoomContinuous-v0", max_linear=0.5)
    try:
        space = env.unwrapped.action_space
        assert isinstance(space, gymnasium.spaces.Box)
        assert list(space.high) == pytest.approx([0.5, 1.5])
        assert env.unwrapped.command_for([2.0, -9.0]) == pytest.approx((0.5, -1.5))
        env.reset(seed=0, options={"start": (-2.0, OPEN_ROW, 0.0), "goal": (2.0, OPEN_ROW)})
        for _ in range(5):
            env.step(np.array([0.3, 0.0], np.float32))
        assert env.unwrapped.scene.velocity()[0] == pytest.approx(0.3, abs=0.01)
    finally:
        env.close()
    with pytest.raises(ConfigError, match="max_linear"):  # the seed robot's wheels: 40 rad/s x 0.032 m
        gymnasium.make("diffbot_sim/GoalRoomContinuous-v0", max_linear=2.0)
    with pytest.raises(ConfigError, match="control_period"):
        gymnasium.make(ROOM, control_period=0.21)
    with pytest.raises(ConfigError, match="GoalEnv colour"):
        gymnasium.make(ROOM, colour="red")


def test_any_robot_in_a_map_world():
    """tests/data/robots/laser_robot.urdf (its lds: 360 samples over 0..2 pi, 0.12 to 10 m) in the maze map
    (worlds/maze.yaml: outer walls' inner faces at x = +-4.8, y = +-3.8), its scan min-pooled to 12 beams."""
    env = gymnasium.make("diffbot_sim/Goal-v0", model="tests/data/robots/laser_robot.urdf",
                         world="worlds/maze.yaml", beams=12, scan_mode="min_pool", laser_noise=False)
    try:
        raw = env.unwrapped
        cells = raw.scene.cells
        assert np.abs(cells[:, 0]).max() < 4.8 - 0.1 and np.abs(cells[:, 1]).max() < 3.8 - 0.1
        assert raw.observation_space.shape == (16,) and raw.observation_space.high[0] == pytest.approx(10.0)
        # at (0, 0) facing +x: the east wall at x = 2.0; its sector (the first of 12, 0..30 degrees) reads
        # the nearest of those beams, 2.0 m less the laser's 0.05 m offset
        obs, _ = env.reset(seed=0, options={"start": (0.0, 0.0, 0.0), "goal": (-1.5, 0.0)})
        assert obs[0] == pytest.approx(2.0 - 0.05, abs=0.01)
        assert obs[-2] == pytest.approx(1.5, abs=1e-5) and abs(obs[-1]) == pytest.approx(math.pi, abs=1e-5)
        assert raw.scene.laser.angles[:2] == pytest.approx([0.0, math.pi / 6], abs=0.01)
    finally:
        env.close()


@pytest.mark.parametrize("mode", ["sync", "async"])
def test_vector_env_of_two(mode):
    if mode == "sync":
        envs = gymnasium.make_vec(ROOM, num_envs=2, vectorization_mode="sync")
    else:  # worker processes started fresh (no fork of this test process): the id names its module
        envs = gymnasium.make_vec("diffbot_sim.gym:" + ROOM, num_envs=2, vectorization_mode="async",
                                  vector_kwargs={"context": "spawn"})
    try:
        obs, _ = envs.reset(seed=[7, 8])
        assert obs.shape == (2, 28) and not np.array_equal(obs[0], obs[1])
        obs, rewards, terminated, truncated, infos = envs.step(np.array([2, 2]))
        assert obs.shape == (2, 28) and rewards.shape == (2,) and infos["sim_time"] == pytest.approx([0.2, 0.2])
    finally:
        envs.close()
