# tier: gl
# cost: 8  (seconds on CI's 2 cores: ctest -j starts the longest first; tests/python/python_tests.cmake)
"""saccade.render and a real camera's photometric chain (docs/camera-pixels.md, docs/sensor.md):
the raw Bayer mosaic of a colour-filter camera against cv2.demosaicing of it, cos^4
vignetting against the formula with optics on and off, and commanded exposure and gain
(SceneState.camera_controls) in the pixels and the metadata. Small images: a few seconds."""

import cv2
import numpy as np
import pytest

import saccade
from conftest import path

# A coloured checker ground and a green box, seen by an RGGB camera with a linear tone curve
# (the image is then the demosaiced mosaic, nothing after it), one without a filter, and one
# whose EMVA sensor exposes its mosaic (colour on) or the RGB image (colour off).
COLOUR_SCENE = """
background: [0.3, 0.5, 0.9]
lights: [{type: ambient, intensity: 0.6}, {type: directional, direction: [1, 0.3, -1], intensity: 0.6}]
ground: {pattern: checker, cell: 0.2, color: [0.9, 0.5, 0.2], color2: [0.1, 0.3, 0.8]}
objects:
  - {name: box, kind: box, size: 0.5, color: [0.2, 0.8, 0.4, 1], pose: {position: [2, 0, 0.25]}}
cameras:
  - name: bayer
    calibration: {width: 96, height: 72, fx: 70, fy: 70}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {color: {cfa: rggb, demosaic: bilinear, white_balance: {red: 1.3, blue: 1.6}}}
  - name: plain
    calibration: {width: 96, height: 72, fx: 70, fy: 70}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
  - name: emva
    calibration: {width: 64, height: 48, fx: 50, fy: 50}
    look_at: {eye: [0, 0, 1], target: [2, 0, 0.3]}
    sensor: {exposure_ms: 8, seed: 5, emva: {preset: imx174}, color: {cfa: bggr}}
    lens: {vignetting: cos4}
"""

# A camera that sees only a white sky (255) through a cos^4 vignetting lens; exposure 10 ms.
WHITE_FIELD = """
background: [1, 1, 1]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
cameras:
  - name: flat
    calibration: {width: 80, height: 60, fx: 45, fy: 50, cx: 40.6, cy: 29.1}
    pose: {position: [0, 0, 1]}
    lens: {vignetting: cos4}
"""

# A grey sky (about 100 DN) for the exposure: no lens effect, no noise, file exposure 10 ms.
GREY_FIELD = """
background: [0.4, 0.4, 0.4]
lights: [{type: ambient, intensity: 1}]
ground: {enabled: false}
cameras:
  - name: grey
    calibration: {width: 64, height: 48, fx: 50, fy: 50}
    pose: {position: [0, 0, 1]}
    sensor: {exposure: 0.01}
"""

# Half a DN: the frames are rounded to integers once after the formula.
ROUNDING_DN = 0.5 + 1e-6


def load(text):
    return saccade.scene.Scene.from_yaml_string(text, "camera_chain_test.yaml",
                                                path("scenes"))


@pytest.fixture(scope="module")
def colour_scene():
    return load(COLOUR_SCENE)


def test_raw_is_the_mosaic_the_colour_image_is_demosaiced_from(colour_scene):
    frames = saccade.render.Renderer(colour_scene).render(colour_scene.initial_state(), 2)
    bayer, plain = frames[:2]
    raw = bayer.raw
    assert raw.dtype == np.uint8 and raw.shape == (72, 96)
    assert bayer.raw_format == "bayer_rggb8"
    assert isinstance(raw.base, saccade.Image) and raw.base.format == "bayer_rggb8"
    assert raw.base.camera == "bayer" and raw.base.frame_index == 2
    assert not raw.flags.writeable
    # A camera without a filter has no mosaic.
    assert plain.raw is None and plain.raw_format is None
    # The scene is coloured: the mosaic's sites differ by colour (the sky's blue sites are
    # brighter than its red ones in the top rows).
    assert raw[0:8:2, 1::2].mean() > 0 and raw[1:8:2, 1::2].mean() > raw[0:8:2, 0::2].mean()
    # With a linear tone curve the image is OpenCV's bilinear demosaicing of the mosaic, bit for
    # bit, borders included (OpenCV names an RGGB mosaic BayerBG, by its second row).
    expected = cv2.demosaicing(np.ascontiguousarray(raw), cv2.COLOR_BayerBG2RGB)
    assert np.array_equal(bayer.color, expected), np.argwhere(bayer.color != expected)[:5]
    # color=False: the plain RGB, no mosaic; the white balance made the image differ from it.
    off = saccade.render.Renderer(colour_scene, color=False).render(
        colour_scene.initial_state(), 2)[0]
    assert off.raw is None
    assert not np.array_equal(off.color, bayer.color)
    # The mosaic samples the plain image's channel at each site, times its white balance gain.
    red_gain, blue_gain = 1.3, 1.6
    assert np.abs(raw[0::2, 0::2] - np.clip(off.color[0::2, 0::2, 0] * red_gain, 0, 255)).max() \
        <= ROUNDING_DN
    assert np.array_equal(raw[0::2, 1::2], off.color[0::2, 1::2, 1])
    assert np.abs(raw[1::2, 1::2] - np.clip(off.color[1::2, 1::2, 2] * blue_gain, 0, 255)).max() \
        <= ROUNDING_DN


def test_set_effects_switches_optics_and_colour_as_the_constructor(colour_scene):
    state = colour_scene.initial_state()
    cameras = ["bayer", "emva"]
    switched = saccade.render.Renderer(colour_scene, cameras=cameras)
    for optics, color in [(True, False), (False, True), (True, True)]:
        switched.set_effects(distortion=True, noise=True, motion_blur=True, optics=optics,
                             color=color)
        got = switched.render(state, 1)
        made = saccade.render.Renderer(colour_scene, cameras=cameras, optics=optics,
                                       color=color).render(state, 1)
        for g, m in zip(got, made):
            assert np.array_equal(g.color, m.color), (g.image.camera, optics, color)
            assert (g.raw is None) == (not color)


def test_vignetting_darkens_the_corners_as_cos4_and_optics_off_does_not():
    field = load(WHITE_FIELD)
    K = field.cameras[0].model.intrinsics
    fx, fy, cx, cy = K.fx, K.fy, K.cx, K.cy
    on = saccade.render.Renderer(field).render(field.initial_state())[0].color
    y, x = np.mgrid[0:60, 0:80]
    cos2 = 1.0 / (1.0 + ((x - cx) / fx) ** 2 + ((y - cy) / fy) ** 2)
    expected = 255.0 * cos2 ** 2
    assert np.abs(on.astype(np.float64) - expected[..., None]).max() <= ROUNDING_DN
    # The corner against the centre: near cos^4 of the corner's ray (about 0.2 here).
    ratio = on[59, 0, 1] / on[29, 41, 1]
    assert ratio < 0.3 and abs(ratio - cos2[59, 0] ** 2) < 0.01
    off = saccade.render.Renderer(field, optics=False).render(field.initial_state())[0].color
    assert (off == 255).all()


def test_commanded_exposure_and_gain_scale_the_image_and_stamp_the_metadata():
    grey = load(GREY_FIELD)
    renderer = saccade.render.Renderer(grey)
    state = grey.initial_state()
    plain = renderer.render(state)[0]
    assert plain.image.exposure_s == pytest.approx(0.01)
    level = plain.color.astype(np.float64)
    assert 90 < level.mean() < 110
    # Half the file's exposure: half the light (docs/sensor.md: scaled by exposure / nominal).
    state.camera_controls = {"grey": saccade.scene.CameraControls(exposure_s=0.005)}
    assert state.camera_controls["grey"].exposure_s == 0.005
    half = renderer.render(state, 1)[0]
    assert half.image.exposure_s == pytest.approx(0.005) and half.image.gain_db == 0.0
    assert np.abs(half.color - level * 0.5).max() <= ROUNDING_DN
    # 6 dB of gain on top: x 10^(6/20) = 1.995 of the half exposure.
    state.camera_controls = {"grey": saccade.scene.CameraControls(exposure_s=0.005, gain_db=6.0)}
    gained = renderer.render(state, 2)[0]
    assert gained.image.gain_db == pytest.approx(6.0)
    factor = 0.5 * 10 ** (6.0 / 20.0)
    assert np.abs(gained.color - np.clip(level * factor, 0, 255)).max() <= ROUNDING_DN
    # A control for a camera the scene does not have, or out of range, is named.
    state.camera_controls = {"nose": saccade.scene.CameraControls(exposure_s=0.01)}
    with pytest.raises(saccade.InvalidArgument, match="nose"):
        renderer.render(state, 3)
    state.camera_controls = {"grey": saccade.scene.CameraControls(exposure_s=2.0)}
    with pytest.raises(saccade.InvalidArgument, match="exposure_s"):
        renderer.render(state, 3)
