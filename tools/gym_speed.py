#!/usr/bin/env python3
"""Speed of the Gymnasium environment (run in the ROS environment, no master needed:
``bash tools/rosenv.sh python3 tools/gym_speed.py``).

1. ``diffbot_sim/GoalRoom-v0`` (the seed robot with its laser in worlds/room.world, 0.2 s control period,
   24-beam laser): ``step()`` calls per second, of wall time and of this process's CPU time (= per core: one
   process, one thread), with seeded random actions (episodes end on collisions often, so resets happen);
   the time spent in ``reset()`` gives resets per second.
2. Bare PyBullet: the same world and robot (the environment's own, loaded the same way, same time step) with
   its wheels set turning once, nothing sensed or controlled, stepped for the same sim time.
3. The ratio of the two in sim seconds per second (goal >= 0.7).

The two are measured in alternating rounds and the medians reported, so a busy machine slows both alike.
Prints one JSON line and a short table.
"""
import argparse
import importlib
import json
import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "src"))


def _clocks():
    return time.perf_counter(), time.process_time()


def env_round(env, steps, actions):
    """(step wall s, step CPU s, sim s stepped, resets, reset wall s, reset CPU s) of ``steps`` steps."""
    step_wall = step_cpu = reset_wall = reset_cpu = 0.0
    sim = 0.0
    resets = 0
    for _ in range(steps):
        w0, c0 = _clocks()
        _, _, terminated, truncated, info = env.step(actions.sample())
        w1, c1 = _clocks()
        step_wall, step_cpu = step_wall + w1 - w0, step_cpu + c1 - c0
        sim = sim + info["sim_time"] - env.unwrapped.last_sim_time
        env.unwrapped.last_sim_time = info["sim_time"]
        if terminated or truncated:
            w0, c0 = _clocks()
            env.reset()
            w1, c1 = _clocks()
            reset_wall, reset_cpu = reset_wall + w1 - w0, reset_cpu + c1 - c0
            env.unwrapped.last_sim_time = 0.0
            resets += 1
    return step_wall, step_cpu, sim, resets, reset_wall, reset_cpu


def bare_round(scene, sim_seconds):
    """(wall s, CPU s) of stepping the scene's world bare for ``sim_seconds`` of sim time."""
    scene.reset(0.0, 0.0, 0.0)
    scene.drive.command(0.1, 0.5)
    scene.drive.before_step(0.0)  # the wheel motors set once; from here on only the physics runs
    world = scene.world
    count = int(round(sim_seconds / scene.cfg.time_step))
    w0, c0 = _clocks()
    for _ in range(count):
        world.step()
    w1, c1 = _clocks()
    return w1 - w0, c1 - c0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=500, help="env steps per round (default 500)")
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds (default 5)")
    parser.add_argument("--id", default="diffbot_sim/GoalRoom-v0")
    parser.add_argument("--scan-mode", default="samples", choices=("samples", "min_pool"))
    args = parser.parse_args()

    import gymnasium

    importlib.import_module("diffbot_sim.gym")  # registers the environments' ids with gymnasium

    env = gymnasium.make(args.id, scan_mode=args.scan_mode)
    env.action_space.seed(0)
    env.reset(seed=0)
    env.unwrapped.last_sim_time = 0.0
    scene = env.unwrapped.scene
    ratios, ratios_cpu, steps_wall, steps_cpu = [], [], [], []
    resets = reset_wall = reset_cpu = 0.0
    for _ in range(args.rounds):
        s_wall, s_cpu, sim, n_resets, r_wall, r_cpu = env_round(env, args.steps, env.action_space)
        b_wall, b_cpu = bare_round(scene, sim)
        env.reset()
        env.unwrapped.last_sim_time = 0.0
        ratios.append((sim / s_wall) / (sim / b_wall))
        ratios_cpu.append((sim / s_cpu) / (sim / b_cpu))
        steps_wall.append(args.steps / s_wall)
        steps_cpu.append(args.steps / s_cpu)
        resets, reset_wall, reset_cpu = resets + n_resets, reset_wall + r_wall, reset_cpu + r_cpu
    w0, c0 = _clocks()
    for seed in range(200):  # resets alone, seeded (each a restore, a placement and a first scan)
        env.reset(seed=seed)
    w1, c1 = _clocks()
    env.close()
    result = {
        "id": args.id, "scan_mode": args.scan_mode, "control_period_s": scene.cfg.control_period,
        "beams": scene.cfg.beams, "time_step_s": scene.cfg.time_step,
        "env_steps_per_s_wall": round(statistics.median(steps_wall), 1),
        "env_steps_per_s_cpu": round(statistics.median(steps_cpu), 1),
        "ratio_to_bare_wall": round(statistics.median(ratios), 3),
        "ratio_to_bare_cpu": round(statistics.median(ratios_cpu), 3),
        "resets_per_s_wall": round(200 / (w1 - w0), 1), "resets_per_s_cpu": round(200 / (c1 - c0), 1),
        "episodes_ended_in_rounds": int(resets),
    }
    print(json.dumps(result))
    print(f"env steps/s        {result['env_steps_per_s_cpu']:8.1f} per CPU-second "
          f"({result['env_steps_per_s_wall']:.1f} per wall second)")
    print(f"ratio to bare      {result['ratio_to_bare_cpu']:8.3f} (CPU), {result['ratio_to_bare_wall']:.3f} (wall); "
          "goal >= 0.7")
    print(f"resets/s           {result['resets_per_s_cpu']:8.1f} per CPU-second "
          f"({result['resets_per_s_wall']:.1f} per wall second)")


if __name__ == "__main__":
    main()
