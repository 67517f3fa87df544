# tier: gl
# cost: 35  (seconds on CI's 2 cores: ctest -j starts the longest first; tests/python/python_tests.cmake)
"""saccade.render: frames as numpy arrays without a copy (ground truth included),
render(out=), batch rendering against single renders, the GIL released while rendering."""

import sys
import threading
import time

import numpy as np
import pytest

import saccade
from conftest import path

# Batch and single renders draw the same pinhole image through the same draw calls. A tile far
# from the framebuffer's origin has window coordinates with less sub-pixel precision (llvmpipe:
# fixed point), so a few edge pixels may fall on the other side of a triangle's edge: measured
# 0.05 % of pixels differ by more than 1 DN at 1024 x 768 (up to 12 such pixels per image).
BATCH_MAX_DIFFERING = 1e-3  # share of pixels off by more than 1 DN
BATCH_MAX_MEAN_DIFF = 0.05  # DN


@pytest.fixture(scope="module")
def scene():
    return saccade.scene.Scene.load(path("scenes", "astronaut_and_cat.yaml"))


@pytest.fixture(scope="module")
def renderer(scene):
    return saccade.render.Renderer(scene, cameras=["left", "right"], truth_depth=True,
                                   truth_ids=True, truth_objects=True)


def test_frames_are_zero_copy_views_of_the_cpp_images(renderer, scene):
    frames = renderer.render(scene.initial_state(), frame_index=3)
    assert [f.image.camera for f in frames] == ["left", "right"]
    frame = frames[0]
    color = frame.color
    assert color.dtype == np.uint8 and color.ndim == 3 and color.shape[2] == 3
    # The array's base is the C++ owner; its memory is the owner's, not a copy.
    assert isinstance(color.base, saccade.Image)
    assert color.ctypes.data == color.base.data_address
    # A second access gives another view of the same memory, no copy.
    assert frame.color.ctypes.data == color.ctypes.data
    assert not color.flags.writeable
    # The owner outlives the frame: the array keeps it alive.
    image = frame.image
    address = image.data_address
    del frames, frame
    assert color.base.data_address == address and color.sum() > 0
    assert np.asarray(image).ctypes.data == address  # the buffer protocol, no copy either
    assert image.frame_index == 3
    # The camera controls the frame was taken with: the file's (no exposure: an instant).
    assert (image.exposure_s, image.gain_db, image.focus_m) == (0.0, 0.0, 0.0)
    assert image.K.shape == (3, 3) and image.X_WC.shape == (4, 4)


def test_ground_truth_depth_and_ids_agree_with_the_projection(renderer, scene):
    state = scene.initial_state()
    frame = renderer.render(state)[0]
    depth, ids = frame.depth, frame.ids
    assert depth.dtype == np.float32 and ids.dtype == np.uint32
    assert isinstance(depth.base, saccade.Image) and isinstance(ids.base, saccade.Image)
    assert depth.shape == ids.shape == frame.color.shape[:2]
    X_WC = scene.camera_pose("left", state)
    model = frame.image.camera_model  # the image as rendered (its lens included)
    # The pictures: their centre lies on their surface, in full view of the left eye.
    seen = [o for o in frame.objects if o.pixels > 0 and o.name in ("astronaut", "chelsea")]
    assert len(seen) == 2, "both pictures are in view"
    for truth in seen:
        # The picture's centre, projected through the camera model.
        p_W = scene.object_pose(truth.name, state)[:3, 3]
        p_C = np.linalg.inv(X_WC) @ np.append(p_W, 1.0)
        u, v = model.project(p_C[:3])
        x_min, y_min, x_max, y_max = truth.box
        assert x_min - 1 <= u <= x_max + 1 and y_min - 1 <= v <= y_max + 1
        assert ids[int(round(v)), int(round(u))] == truth.id
        # Depth is the z of the surface point in the camera frame: at the centre, near p_C's z.
        assert abs(depth[int(round(v)), int(round(u))] - p_C[2]) < 0.05


def test_render_out_fills_the_callers_array(renderer, scene):
    state = scene.initial_state()
    frames = renderer.render(state)
    h, w, _ = frames[0].color.shape
    out = np.zeros((2, h, w, 3), np.uint8)
    returned = renderer.render(state, out=out)
    assert returned is out
    assert np.array_equal(out[0], frames[0].color) and np.array_equal(out[1], frames[1].color)
    with pytest.raises(saccade.InvalidArgument, match=r"out must be a uint8 array of shape \(2, "):
        renderer.render(state, out=np.zeros((2, h, w), np.uint8))
    with pytest.raises(saccade.InvalidArgument, match="C-contiguous"):
        renderer.render(state, out=np.zeros((2, h, w, 6), np.uint8)[..., ::2])


def test_batch_equals_single_renders_of_each_head(scene):
    single = saccade.render.Renderer(scene, cameras=["left", "right"], distortion=False,
                                     noise=False, motion_blur=False)
    rng = np.random.default_rng(5)
    states = [saccade.scene.SceneState(0.0, rng.uniform(-0.2, 0.2, 4)) for _ in range(5)]
    batch = single.render_batch([saccade.render.BatchHead(s) for s in states])
    assert batch.shape[:2] == (5, 2) and batch.dtype == np.uint8
    # The first tile lies where a batch of one puts it: the same pixels, to the bit.
    assert np.array_equal(single.render_batch([saccade.render.BatchHead(states[0])])[0], batch[0])
    for i, state in enumerate(states):
        frames = single.render(state)
        for c in range(2):
            diff = np.abs(batch[i, c].astype(int) - frames[c].color.astype(int))
            assert (diff > 1).mean() <= BATCH_MAX_DIFFERING, (i, c, (diff > 1).sum())
            assert diff.mean() <= BATCH_MAX_MEAN_DIFF, (i, c, diff.mean())
    # Different joints give different images: every head is drawn with its own state.
    assert not np.array_equal(batch[0, 0], batch[1, 0])


def test_batch_contexts_one_and_two_give_the_same_images(scene):
    states = [saccade.scene.SceneState(0.0, [0.04 * i, -0.05, 0.02, -0.02]) for i in range(3)]
    images = []
    for contexts in (1, 2):
        r = saccade.render.Renderer(scene, cameras=["left", "right"], distortion=False,
                                    noise=False, motion_blur=False, batch_contexts=contexts)
        images.append(r.render_batch([saccade.render.BatchHead(s) for s in states]))
    assert np.array_equal(images[0], images[1])
    assert not np.array_equal(images[1][0, 1], images[1][2, 1])  # the second context's half drew
    with pytest.raises(saccade.InvalidArgument, match="batch_contexts must be 0 .automatic., 1 or 2, got 3"):
        saccade.render.Renderer(scene, batch_contexts=3)


def test_batch_heads_have_their_own_objects(scene):
    r = saccade.render.Renderer(scene, cameras=["left"], distortion=False, noise=False,
                                motion_blur=False, draw_robot=False)
    state = scene.initial_state()
    n = len(scene.objects)
    shown = saccade.render.BatchHead(state)
    hidden = saccade.render.BatchHead(state, hidden=[True] * n)
    moved_poses = [scene.object_pose(o.name, state) for o in scene.objects]
    for X in moved_poses:
        X[1, 3] += 0.3
    moved = saccade.render.BatchHead(state, object_poses=moved_poses)
    out = np.zeros((3, 1) + single_shape(r, scene), np.uint8)
    r.render_batch([shown, hidden, moved], out=out)
    assert not np.array_equal(out[0], out[1]) and not np.array_equal(out[0], out[2])
    # With every object hidden, only the sky and the ground remain: fewer distinct colours.
    assert len(np.unique(out[1].reshape(-1, 3), axis=0)) < len(np.unique(out[0].reshape(-1, 3), axis=0))
    with pytest.raises(saccade.InvalidArgument, match="hidden has 1 entries"):
        r.render_batch([saccade.render.BatchHead(state, hidden=[True])])
    with pytest.raises(saccade.InvalidArgument, match="rigid transform"):
        saccade.render.BatchHead(state, object_poses=[np.zeros((4, 4))] * n)


def single_shape(r, scene):
    frame = r.render(scene.initial_state())[0]
    return frame.color.shape


def test_rendering_releases_the_gil(scene):
    r = saccade.render.Renderer(scene, cameras=["left", "right"], distortion=False, noise=False,
                                motion_blur=False)
    heads = [saccade.render.BatchHead(scene.initial_state())] * 16
    r.render_batch(heads)  # warm up
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.0005)

    old = sys.getswitchinterval()
    sys.setswitchinterval(1.0)  # a thread holding the GIL would starve the counter
    try:
        thread = threading.Thread(target=count)
        thread.start()
        time.sleep(0.01)
        start = len(ticks)
        t0 = time.perf_counter()
        r.render_batch(heads)
        elapsed = time.perf_counter() - t0
        during = len(ticks) - start
        stop.set()
        thread.join()
    finally:
        sys.setswitchinterval(old)
    assert elapsed > 0.02, "the batch is long enough to tell"
    assert during >= 5, f"the counter ran {during} times during {elapsed:.3f} s of rendering"


def test_unknown_camera_is_named(scene):
    with pytest.raises(saccade.InvalidArgument, match="nose"):
        saccade.render.Renderer(scene, cameras=["nose"])


def test_set_effects_gives_the_frames_of_a_renderer_made_with_them():
    # The bench scene's eyes have a lens, sensor noise and an exposure; the head pans (blur).
    bench = saccade.scene.Scene.load(path("scenes", "bench.yaml"))
    state = bench.initial_state()
    state.time = 0.1
    velocities = state.joint_velocities
    velocities.pan = 2.0
    state.joint_velocities = velocities
    switched = saccade.render.Renderer(bench, cameras=["left"])
    images = []
    for distortion, noise, blur in [(False, True, False), (True, False, True), (True, True, True)]:
        switched.set_effects(distortion=distortion, noise=noise, motion_blur=blur)
        got = switched.render(state, 3)[0]
        made = saccade.render.Renderer(bench, cameras=["left"], distortion=distortion,
                                       noise=noise, motion_blur=blur).render(state, 3)[0]
        assert np.array_equal(got.color, made.color), (distortion, noise, blur)
        images.append(got.color.copy())
    assert not np.array_equal(images[0], images[1]) and not np.array_equal(images[1], images[2])


def test_stats_say_what_the_cpu_did_of_the_effects():
    # The bench scene's eyes, head still: on a software rasteriser (llvmpipe here) the lens
    # remap and the noise run on the CPU after readback, and the stats count them within
    # readback; a GPU does them in its final pass.
    bench = saccade.scene.Scene.load(path("scenes", "bench.yaml"))
    r = saccade.render.Renderer(bench, cameras=["left"])
    r.render(bench.initial_state(), 0)
    stats = r.stats
    assert stats.frames == 1
    if "llvmpipe" in r.device or "softpipe" in r.device:
        assert 0.0 < stats.cpu_effects_ms <= stats.readback_ms
    else:
        assert stats.cpu_effects_ms == 0.0
    plain = saccade.render.Renderer(bench, cameras=["left"], distortion=False, noise=False)
    plain.render(bench.initial_state(), 0)
    assert plain.stats.cpu_effects_ms == 0.0
