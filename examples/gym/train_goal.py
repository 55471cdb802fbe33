#!/usr/bin/env python3
"""Train a small policy to reach goals in the room (``diffbot_sim/GoalRoom-v0``) with Stable-Baselines3's PPO,
and draw its learning curve.

An optional extra, not installed by ``make setup``; into the project's venv::

    bash tools/rosenv.sh python3 -m pip install torch==2.13.0 stable-baselines3
    bash tools/rosenv.sh python3 examples/gym/train_goal.py            # ~200k steps, one core

What it does: 8 environments in one process (``DummyVecEnv``, so one core), observations rescaled to
[-1, 1] from the environment's own bounds, PPO with a 64x64 MLP. Every ``--eval-every`` steps the current
policy (deterministic) drives ``--eval-episodes`` fixed-seed episodes (the same starts and goals each time):
their success rate and mean return are the curve's points; the training episodes' returns are drawn too.
Writes the curve (default docs/gym_learning_curve.png), and optionally the figures as JSON (``--figures``)
and the policy (``--save``).
"""
import argparse
import json
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "src"))


def make_env(env_id, **kwargs):
    """One environment as the agent sees it: observations rescaled to [-1, 1] from the Box's bounds."""
    import importlib

    import gymnasium
    import numpy as np

    importlib.import_module("diffbot_sim.gym")  # registers the environments' ids with gymnasium

    env = gymnasium.make(env_id, **kwargs)
    low, high = env.observation_space.low, env.observation_space.high
    return gymnasium.wrappers.RescaleObservation(env, -np.ones_like(low), np.ones_like(high))


def evaluate(model, env, seeds):
    """(success rate, mean return, mean steps) of the deterministic policy over one episode per seed."""
    successes, returns, lengths = 0, [], []
    for seed in seeds:
        obs, _ = env.reset(seed=seed)
        total, steps, done = 0.0, 0, False
        while not done:
            action, _ = model.predict(obs, deterministic=True)
            obs, reward, terminated, truncated, info = env.step(action)
            total, steps, done = total + reward, steps + 1, terminated or truncated
        successes += bool(info.get("is_success"))
        returns.append(total)
        lengths.append(steps)
    return successes / len(seeds), sum(returns) / len(returns), sum(lengths) / len(lengths)


def plot(points, episodes, path, title):
    """The curve: evaluation success rate and return against training steps, training returns behind."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, (ax_success, ax_return) = plt.subplots(2, 1, figsize=(7.5, 6.5), sharex=True)
    steps = [p["steps"] for p in points]
    ax_success.plot(steps, [100 * p["success_rate"] for p in points], "o-", color="tab:green",
                    label="evaluation (deterministic policy)")
    if episodes:
        window = max(1, len(episodes) // 40)
        reached = np.convolve([100.0 * e[2] for e in episodes], np.ones(window) / window, mode="valid")
        ax_success.plot([e[0] for e in episodes][window - 1:], reached, color="tab:blue",
                        label=f"training episodes, mean of {window}")
    ax_success.legend(loc="upper left", fontsize=8)
    ax_success.set_ylabel("goals reached, % of episodes")
    ax_success.set_ylim(-5, 105)
    ax_success.grid(alpha=0.3)
    ax_success.set_title(title, fontsize=10)
    if episodes:
        ends = np.array([e[0] for e in episodes])
        returns = np.array([e[1] for e in episodes])
        window = max(1, len(returns) // 40)
        smooth = np.convolve(returns, np.ones(window) / window, mode="valid")
        ax_return.plot(ends, returns, ".", color="0.8", markersize=2, label="training episodes")
        ax_return.plot(ends[window - 1:], smooth, color="tab:blue", label=f"training, mean of {window}")
    ax_return.plot(steps, [p["mean_return"] for p in points], "o-", color="tab:orange", label="evaluation")
    ax_return.set_xlabel("environment steps (0.2 s of sim time each)")
    ax_return.set_ylabel("episode return")
    ax_return.grid(alpha=0.3)
    ax_return.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--env", default="diffbot_sim/GoalRoom-v0")
    parser.add_argument("--steps", type=int, default=200_000, help="training steps (default 200000)")
    parser.add_argument("--envs", type=int, default=8, help="environments stepped together (default 8)")
    parser.add_argument("--eval-every", type=int, default=20_000)
    parser.add_argument("--eval-episodes", type=int, default=40)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "gym_learning_curve.png"))
    parser.add_argument("--figures", default="", help="where to write the figures (.json); empty: not written")
    parser.add_argument("--save", default="", help="where to save the policy (.zip); empty: not saved")
    args = parser.parse_args()

    try:
        import torch
        from stable_baselines3 import PPO
        from stable_baselines3.common.callbacks import BaseCallback
        from stable_baselines3.common.vec_env import DummyVecEnv, VecMonitor
    except ImportError as err:
        sys.exit(f"train_goal: {err}; install the optional extra: python3 -m pip install torch==2.13.0 "
                 "stable-baselines3")
    torch.set_num_threads(1)  # one core: the environments and the network share it

    train = VecMonitor(DummyVecEnv([lambda: make_env(args.env) for _ in range(args.envs)]))
    evaluation = make_env(args.env)
    eval_seeds = list(range(10_000, 10_000 + args.eval_episodes))
    model = PPO("MlpPolicy", train, n_steps=256, batch_size=256, n_epochs=10, gamma=0.99, learning_rate=3e-4,
                ent_coef=0.01, seed=args.seed, verbose=0, device="cpu")
    points, episodes, started = [], [], time.process_time()

    def record(steps):
        success, mean_return, mean_steps = evaluate(model, evaluation, eval_seeds)
        points.append({"steps": steps, "success_rate": success, "mean_return": round(mean_return, 2),
                       "mean_episode_steps": round(mean_steps, 1),
                       "cpu_s": round(time.process_time() - started, 1)})
        print(json.dumps(points[-1]), flush=True)

    class Recorder(BaseCallback):
        """Training episodes' returns as they end; an evaluation every ``--eval-every`` steps."""

        def _on_step(self):
            for info in self.locals["infos"]:
                if "episode" in info:
                    episodes.append((self.num_timesteps, info["episode"]["r"], bool(info.get("is_success"))))
            if self.num_timesteps // args.eval_every > (self.num_timesteps - args.envs) // args.eval_every:
                record(self.num_timesteps)
            return True

    train.seed(args.seed)
    record(0)
    model.learn(total_timesteps=args.steps, callback=Recorder())
    cpu = time.process_time() - started
    title = (f"PPO (Stable-Baselines3) on {args.env}: {args.steps:,} steps, {args.envs} envs, one core,\n"
             f"{cpu / 60:.0f} min CPU; evaluation: {args.eval_episodes} fixed starts and goals")
    plot(points, episodes, args.out, title)
    if args.figures:
        with open(args.figures, "w") as out:
            json.dump({"env": args.env, "steps": args.steps, "envs": args.envs, "cpu_s": round(cpu, 1),
                       "training_episodes": len(episodes), "evaluations": points,
                       "episodes": [[s, round(float(r), 2), g] for s, r, g in episodes]}, out)
    if args.save:
        model.save(args.save)
    print(f"train_goal: {len(episodes)} training episodes, {cpu / 60:.1f} min CPU; curve {args.out}")


if __name__ == "__main__":
    main()
