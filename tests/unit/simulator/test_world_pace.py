"""How a world's <physics> block paces the simulator (simulator.robots.apply_world_physics), as Gazebo paces
itself: real_time_update_rate x max_step_size is the real-time factor, rate 0 runs as fast as the nodes in the
loop allow; the node's own parameters win."""
import pytest

from diffbot_sim.config import SimConfig
from diffbot_sim.simulator.robots import apply_world_physics
from diffbot_sim.world.bodies import WorldDescription


def world(**physics):
    return WorldDescription(name="w", source="w.world", **physics)


def test_rate_times_step_is_the_real_time_factor():
    cfg = SimConfig()
    apply_world_physics(cfg, world(real_time_update_rate=5000.0, max_step_size=0.001), {})
    assert cfg.real_time and cfg.real_time_factor == pytest.approx(5.0)


def test_rate_zero_is_fast_mode():
    cfg = SimConfig()
    apply_world_physics(cfg, world(real_time_update_rate=0.0, max_step_size=0.001, real_time_factor=1.0), {})
    assert not cfg.real_time and cfg.wait_for_nodes


def test_the_nodes_parameters_win():
    cfg = SimConfig(real_time=True, real_time_factor=2.0)
    apply_world_physics(cfg, world(real_time_update_rate=0.0), {"real_time": True, "real_time_factor": 2.0})
    assert cfg.real_time and cfg.real_time_factor == 2.0


def test_without_a_rate_the_factor_tag_applies():
    cfg = SimConfig()
    apply_world_physics(cfg, world(real_time_factor=3.0), {})
    assert cfg.real_time and cfg.real_time_factor == 3.0
