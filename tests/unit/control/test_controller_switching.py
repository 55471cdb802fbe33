"""controller_switching: controller_manager's load / switch / unload rules (what the spawner and the
controller_manager command rely on)."""
import pytest

from diffbot_sim.control.controller_switching import (
    BEST_EFFORT,
    STRICT,
    SwitchError,
    check_load,
    check_unload,
    plan_switch,
)

CLAIMS = {"base": {"l", "r"}, "jsc": set(), "left_only": {"l"}, "arm": {"a"}}


def test_stop_then_start_in_request_order():
    assert plan_switch(CLAIMS, ["base", "jsc"], CLAIMS, ["arm"], ["jsc"], STRICT) == (["jsc"], ["arm"])


@pytest.mark.parametrize("start, stop, needle", [
    (["nobody"], [], "no controller with this name exists"),
    (["base"], [], "already running"),
    ([], ["arm"], "not running"),
    ([], ["nobody"], "no controller with this name exists"),
])
def test_strict_refuses_the_whole_request(start, stop, needle):
    with pytest.raises(SwitchError, match=needle):
        plan_switch(CLAIMS, ["base", "jsc"], CLAIMS, start, stop, STRICT)


@pytest.mark.parametrize("strictness", [BEST_EFFORT, 0])
def test_best_effort_skips_what_it_cannot_do(strictness):
    assert plan_switch(CLAIMS, ["base"], CLAIMS, ["nobody", "base", "arm"], ["jsc"], strictness) == ([], ["arm"])


def test_restarting_a_stopped_one_in_the_same_request():
    assert plan_switch(CLAIMS, ["base"], CLAIMS, ["base"], ["base"], STRICT) == (["base"], ["base"])


@pytest.mark.parametrize("strictness", [BEST_EFFORT, STRICT])
def test_two_running_controllers_may_not_claim_one_joint(strictness):
    with pytest.raises(SwitchError, match="joint 'l'"):
        plan_switch(CLAIMS, ["base"], CLAIMS, ["left_only"], [], strictness)
    assert plan_switch(CLAIMS, ["base"], CLAIMS, ["left_only"], ["base"], strictness) == (["base"], ["left_only"])


def test_unload_needs_a_stopped_known_controller():
    check_unload("arm", CLAIMS, ["base"])
    with pytest.raises(SwitchError, match="still running"):
        check_unload("base", CLAIMS, ["base"])
    with pytest.raises(SwitchError, match="no controller"):
        check_unload("nobody", CLAIMS, [])


def test_load_needs_a_known_type_and_a_new_name():
    known = {"diff_drive_controller/DiffDriveController"}
    assert check_load("base", {}, {"type": "diff_drive_controller/DiffDriveController"}, known)
    with pytest.raises(SwitchError, match="already loaded"):
        check_load("base", {"base": 1}, {"type": "x"}, known)
    with pytest.raises(SwitchError, match="type was not specified"):
        check_load("base", {}, None, known)
    with pytest.raises(SwitchError, match="'x' does not exist"):
        check_load("base", {}, {"type": "x"}, known)
