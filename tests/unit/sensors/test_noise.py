"""diffbot_sim.sensors.noise: SDF <noise> and plugin noise, seeded (no ROS)."""
import math
import statistics
import xml.etree.ElementTree as ET

import pytest

from diffbot_sim.errors import ModelError
from diffbot_sim.sensors import noise


def samples(model, n=20000, value=0.0):
    return [model(value) for _ in range(n)]


def test_same_seed_and_name_give_the_same_stream_others_differ():
    a = [noise.rng(0, "imu").gauss(0, 1) for _ in range(3)]
    assert a == [noise.rng(0, "imu").gauss(0, 1) for _ in range(3)]
    assert a != [noise.rng(1, "imu").gauss(0, 1) for _ in range(3)]
    assert a != [noise.rng(0, "imu2").gauss(0, 1) for _ in range(3)]


def test_gaussian_statistics_with_a_fixed_seed():
    model = noise.Gaussian(noise.rng(0, "x"), mean=0.5, stddev=0.2)
    values = samples(model)
    assert statistics.fmean(values) == pytest.approx(0.5, abs=0.01)
    assert statistics.pstdev(values) == pytest.approx(0.2, rel=0.03)
    assert model.variance == pytest.approx(0.04)


def test_bias_is_drawn_once_with_a_random_sign():
    signs = set()
    for i in range(20):
        model = noise.Gaussian(noise.rng(i, "b"), bias_mean=1.0)
        assert abs(model.bias) == 1.0
        signs.add(model.bias > 0)
        assert model(0.0) == model.bias  # no stddev: the bias alone, every time
    assert signs == {True, False}


def test_sdf_noise_element_forms():
    el = ET.fromstring('<noise type="gaussian"><mean>0</mean><stddev>2e-4</stddev>'
                       '<bias_mean>7.5e-6</bias_mean><bias_stddev>8e-7</bias_stddev></noise>')
    model = noise.sdf_noise(el, noise.rng(0, "s"), "here")
    assert (model.stddev, model.bias_mean, model.bias_stddev) == (2e-4, 7.5e-6, 8e-7)
    assert noise.sdf_noise(ET.fromstring('<noise type="none"/>'), noise.rng(0, "s"), "here") is None
    assert noise.sdf_noise(None, noise.rng(0, "s"), "here") is None
    old = ET.fromstring("<rate><type>gaussian</type><stddev>0.1</stddev></rate>")  # SDF 1.4 style child <type>
    assert noise.sdf_noise(old, noise.rng(0, "s"), "here").stddev == 0.1


def test_quantized_noise_rounds_to_the_precision():
    el = ET.fromstring('<noise type="gaussian_quantized"><stddev>0.01</stddev><precision>0.5</precision></noise>')
    model = noise.sdf_noise(el, noise.rng(0, "q"), "here")
    for v in samples(model, 200, 1.1):
        assert v in (0.5, 1.0, 1.5)


@pytest.mark.parametrize("xml", ['<noise type="pink"/>', '<noise type="gaussian"><stddev>x</stddev></noise>',
                                 '<noise type="gaussian"><stddev>-1</stddev></noise>'])
def test_bad_sdf_noise_names_the_place(xml):
    with pytest.raises(ModelError, match="sensor\\[@name='imu'\\]"):
        noise.sdf_noise(ET.fromstring(xml), noise.rng(0, "s"), "/robot/gazebo/sensor[@name='imu']")


def test_hector_model_tags_defaults_and_statistics():
    tags = {"accelOffset": "0.1 0.2 0.3", "accelGaussianNoise": "0.05", "accelScaleError": "1.01"}
    models = noise.hector_models(tags, "accel", noise.rng(0, "h"), "here")
    assert [m.offset for m in models] == [0.1, 0.2, 0.3]
    assert all(m.gaussian_noise == 0.05 and m.scale_error == 1.01 for m in models)
    assert all(m.drift == 0 and m.drift_frequency == pytest.approx(1 / 3600) for m in models)
    values = [models[2](10.0, 0.01) for _ in range(20000)]
    assert statistics.fmean(values) == pytest.approx(10.1 + 0.3, abs=0.005)
    assert statistics.pstdev(values) == pytest.approx(0.05, rel=0.03)
    assert noise.hector_tag_names("yaw") == ("yawOffset", "yawDrift", "yawDriftFrequency",
                                            "yawGaussianNoise", "yawScaleError")


def test_hector_drift_is_stationary_with_its_stddev():
    model = noise.HectorModel(noise.rng(0, "d"), drift=0.3, drift_frequency=1.0)
    values = []
    for _ in range(50000):
        model.update(0.1)
        values.append(model.current_drift)
    assert statistics.pstdev(values) == pytest.approx(0.3, rel=0.1)
    assert abs(statistics.fmean(values)) < 0.05


def test_hector_bad_vector_names_the_tag():
    with pytest.raises(ModelError, match="accelOffset"):
        noise.hector_models({"accelOffset": "1 2"}, "accel", noise.rng(0, "h"), "here")
    assert math.isclose(noise.plain(noise.rng(0, "p"), 0.1).variance, 0.01)
