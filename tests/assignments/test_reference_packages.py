"""Tests for the reference ROS 2 packages in assignments/reference_ws/src: webcam and readmarker.

- readmarker.crop.crop_pictures (the plain function) against the ground truth of rendered
  scenes: right crops on easy and hard scenes, no crop without all four markers, no crash on
  odd frames;
- readmarker.marker_reader.MarkerReader in this process over real Fast DDS (its message package
  catdog_interfaces built first): mono8/rgb8 input, bad messages skipped;
- slow: a real `colcon build` of the catdog_warp packages into a temporary workspace (as the
  grader builds them: autograder.builds.workspace_build, interface packages from a cache), then the installed
  executables run as processes (like `ros2 run`) in a reserved ROS domain;
- every assignment's reference packages build, and their solution regions are marked.
"""

import os
import time
import xml.etree.ElementTree as ElementTree

import cv2
import numpy as np
import pytest
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from sensor_msgs.msg import Image
from support.from_source import reference_module

from course_lib import contract
from course_lib.checks import assignments
from course_lib.imaging import images, marker_board, pictures, scenes
from course_lib.ros import rosenv, workspace

SOURCE = contract.ROOT / "assignments" / "reference_ws" / "src"
PACKAGES = ("webcam", "readmarker")
BOARD_IDS = tuple(i for ids in marker_board.PICTURES.values() for i in ids)

crop_module = reference_module("readmarker.crop")  # the package's modules, as colcon would install them
crop_pictures, find_markers = crop_module.crop_pictures, crop_module.find_markers

#: The picture of each CroppedPicture.picture number.
PICTURE_NAMES = {1: "cat", 2: "dog"}

WAIT = 60.0  # a bound on every wait for messages, not a speed goal (a busy machine takes seconds)


def spin_until(executor, condition, timeout=WAIT, every=None):
    """Spin until condition() is true (returns True) or timeout seconds pass (returns False)."""
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() >= deadline:
            return False
        if every is not None:
            every()
        executor.spin_once(timeout_sec=0.05)
    return True


def stamp_of(msg):
    return msg.header.stamp.sec, msg.header.stamp.nanosec


# ---- crop_pictures --------------------------------------------------------------------------

def test_crops_match_the_expected_crops_on_easy_and_hard_scenes():
    """Every fully framed picture is found, and every crop returned is that picture (>= threshold)."""
    framed = {"easy": 0, "hard": 0}
    found = 0
    for difficulty, seeds in (("easy", range(8)), ("hard", range(100, 148))):
        for seed in seeds:
            scene = scenes.render_scene(seed, difficulty=difficulty)
            crops = crop_pictures(scene.frame)
            expected = scene.expected_crops()
            framed[difficulty] += len(scene.fully_framed)
            for name in scene.fully_framed:
                assert name in crops, f"{difficulty} seed {seed}: the {name} is fully framed but was not cropped"
            for name, crop in crops.items():
                found += 1
                assert crop.shape == (240, 320, 3) and crop.dtype == np.uint8
                # Markers a little smaller than scenes.MIN_MARKER_SIDE are often found too; then
                # they must at least be printed, uncovered and in the frame.
                assert set(marker_board.PICTURES[name]) <= set(scene.visible_ids), f"{difficulty} seed {seed} {name}"
                score = marker_board.crop_similarity(crop, expected[name])
                assert score >= marker_board.SAME_CROP_THRESHOLD, f"{difficulty} seed {seed} {name}: {score:.3f}"
    # The sample really exercises the claim (it has 16 easy and 18 hard fully framed pictures).
    assert framed["easy"] >= 12 and framed["hard"] >= 12 and found >= sum(framed.values()), (framed, found)


def test_crop_size_is_width_by_height():
    scene = scenes.render_scene(1)
    crops = crop_pictures(scene.frame, size=(160, 90))
    expected = scene.expected_crops((160, 90))
    assert sorted(crops) == ["cat", "dog"]
    for name, crop in crops.items():
        assert crop.shape == (90, 160, 3)
        assert marker_board.crop_similarity(crop, expected[name]) >= marker_board.SAME_CROP_THRESHOLD


@pytest.mark.parametrize("marker_id", BOARD_IDS)
@pytest.mark.parametrize("how", ["missing", "occluded"])
def test_a_picture_missing_one_marker_is_absent(marker_id, how):
    option = {"missing_markers" if how == "missing" else "occluded_markers": (marker_id,)}
    scene = scenes.render_scene(20 + marker_id, **option)
    crops = crop_pictures(scene.frame)
    incomplete = next(name for name, ids in marker_board.PICTURES.items() if marker_id in ids)
    assert incomplete not in crops
    for name in scene.fully_framed:
        assert name in crops


@pytest.mark.parametrize("printed", range(9))
def test_boards_with_zero_to_eight_markers_give_the_complete_pictures(printed):
    scene = scenes.render_scene(6, missing_markers=BOARD_IDS[printed:])
    complete = [name for name, ids in marker_board.PICTURES.items() if set(ids) <= set(BOARD_IDS[:printed])]
    assert sorted(crop_pictures(scene.frame)) == sorted(complete)


def test_of_a_duplicated_id_the_largest_instance_counts():
    marker = cv2.aruco.generateImageMarker(marker_board.dictionary(), 3, 60)
    frame = np.full((300, 400), 255, np.uint8)
    frame[40:100, 40:100] = marker
    frame[120:240, 200:320] = cv2.resize(marker, (120, 120), interpolation=cv2.INTER_NEAREST)
    markers = find_markers(cv2.cvtColor(frame, cv2.COLOR_GRAY2BGR))
    assert sorted(markers) == [3]
    np.testing.assert_allclose(markers[3].min(axis=0), (200, 120), atol=2)
    np.testing.assert_allclose(markers[3].max(axis=0), (319, 239), atol=2)


@pytest.mark.parametrize("seed, difficulty, duplicates", [
    (7, "easy", (3, 6)), (8, "easy", BOARD_IDS), (9, "hard", BOARD_IDS), (10, "easy", (0, 9, 49))])
def test_duplicated_marker_ids_do_not_crash(seed, difficulty, duplicates):
    scene = scenes.render_scene(seed, difficulty=difficulty, duplicate_markers=duplicates)
    crops = crop_pictures(scene.frame)
    assert set(crops) <= set(marker_board.PICTURES)
    for crop in crops.values():
        assert crop.shape == (240, 320, 3) and crop.dtype == np.uint8


@pytest.mark.parametrize("size", [(64, 48), (1920, 1080)])
def test_tiny_and_full_hd_frames(size):
    scene = scenes.render_scene(3, size=size)
    crops = crop_pictures(scene.frame)
    assert set(scene.fully_framed) <= set(crops)
    expected = scene.expected_crops()
    for name, crop in crops.items():
        assert crop.shape == (240, 320, 3)
        assert marker_board.crop_similarity(crop, expected[name]) >= marker_board.SAME_CROP_THRESHOLD
    if size == (1920, 1080):
        assert sorted(crops) == ["cat", "dog"]


@pytest.mark.parametrize("frame", [
    np.zeros((1, 1, 3), np.uint8), np.zeros((480, 640, 3), np.uint8), np.full((48, 64), 255, np.uint8),
    np.random.default_rng(0).integers(0, 256, (480, 640, 3), dtype=np.uint8),
], ids=["1x1", "black", "white grey", "noise"])
def test_frames_without_a_board_give_no_crops(frame):
    assert crop_pictures(frame) == {}


def test_grey_frames_give_bgr_crops_of_the_same_pictures():
    scene = scenes.render_scene(2)
    grey = cv2.cvtColor(scene.frame, cv2.COLOR_BGR2GRAY)
    expected = scene.expected_crops()
    for frame in (grey, grey[:, :, None]):
        crops = crop_pictures(frame)
        assert sorted(crops) == ["cat", "dog"]
        for name, crop in crops.items():
            assert crop.shape == (240, 320, 3)
            assert marker_board.crop_similarity(crop, expected[name]) >= marker_board.SAME_CROP_THRESHOLD


@pytest.mark.parametrize("frame, size, message", [
    (np.zeros((48, 64, 3), np.float32), (320, 240), "uint8"),
    (np.zeros((48, 64, 4), np.uint8), (320, 240), "BGR image"),
    (np.zeros((0, 64, 3), np.uint8), (320, 240), "BGR image"),
    (np.zeros((48, 64, 3), np.uint8), 320, "width, height"),
    (np.zeros((48, 64, 3), np.uint8), (1, 240), "at least 2x2"),
])
def test_bad_arguments_are_refused_with_the_fix(frame, size, message):
    with pytest.raises(ValueError, match=message):
        crop_pictures(frame, size)


# ---- MarkerReader in this process -----------------------------------------------------------

@pytest.fixture(scope="module", autouse=True)
def environment_restored():
    """use_interfaces sources a workspace into this process's environment; test modules that run
    later on this worker (and the processes they start) must not inherit its paths."""
    saved = dict(os.environ)
    yield
    os.environ.clear()
    os.environ.update(saved)


def use_interfaces(ws):
    """Import catdog_interfaces (which marker_reader imports) in this process: the underlay the
    build used (readmarker itself is imported from its source, above)."""
    for install in sorted((ws.parent / ".colcon" / "underlays").glob("*/install")):
        workspace.use_workspace(install.parent)


@pytest.mark.slow
def test_marker_reader_accepts_bgr_rgb_mono_and_skips_bad_images(built_ws, domain_id):
    """rgb8 gives the bgr8 crops, mono8 grey ones of the same pictures; bad images only count."""
    use_interfaces(built_ws)
    from catdog_interfaces.msg import CroppedPicture
    from readmarker.marker_reader import MarkerReader

    scene = scenes.render_scene(4)
    frame = scene.frame
    good = {
        "bgr8": images.image_to_msg(frame, "bgr8"),
        "rgb8": images.image_to_msg(cv2.cvtColor(frame, cv2.COLOR_BGR2RGB), "rgb8"),
        "mono8": images.image_to_msg(cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY), "mono8"),
    }
    truncated = images.image_to_msg(frame, "bgr8")
    truncated.data = truncated.data[:1000]
    unknown = images.image_to_msg(frame, "bgr8")
    unknown.encoding = "yuv422"
    deep = images.image_to_msg(np.zeros((48, 64), np.uint16), "mono16")  # needs a scale to be bgr8
    bad = [truncated, unknown, deep]
    sequence = [("bgr8", good["bgr8"]), *(("bad", msg) for msg in bad), ("rgb8", good["rgb8"]),
                ("mono8", good["mono8"])]
    for index, (_, msg) in enumerate(sequence):
        msg.header.stamp.sec = index + 1

    received = {name: [] for name in marker_board.PICTURES}
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        reader = MarkerReader(context=context, parameter_overrides=[Parameter("width", value=200),
                                                                    Parameter("height", value=150)])
        tester = Node("tester", context=context)
        publisher = tester.create_publisher(Image, "image", 10)
        tester.create_subscription(CroppedPicture, "cropped_img",
                                   lambda msg: received[PICTURE_NAMES[msg.picture]].append(msg.image), 50)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(reader)
        executor.add_node(tester)
        assert spin_until(executor, lambda: publisher.get_subscription_count() > 0), "reader never matched"

        def deliver(msg, frames_before: int) -> bool:
            """One image at a time (the reader keeps the last few only), sent again if one was lost."""
            return spin_until(executor, lambda: reader.frames_received > frames_before,
                              every=lambda: publisher.publish(msg))

        for index, (_, msg) in enumerate(sequence):
            assert deliver(msg, index), f"image {index} never arrived"
        assert spin_until(executor, lambda: all(len(received[n]) >= 3 for n in received)), received
        executor.shutdown()
        reader.destroy_node()
        tester.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)

    assert reader.bad_frames >= len(bad)
    encoding_of = {index + 1: encoding for index, (encoding, _) in enumerate(sequence)}
    expected = scene.expected_crops((200, 150))
    for name, messages in received.items():
        crops = {}
        for msg in messages:
            assert encoding_of[msg.header.stamp.sec] != "bad"
            crops[encoding_of[msg.header.stamp.sec]] = images.compressed_to_image(msg)
        assert sorted(crops) == ["bgr8", "mono8", "rgb8"], f"{name}: one crop per good image"
        assert all(crop.shape == (150, 200, 3) for crop in crops.values())
        np.testing.assert_array_equal(crops["rgb8"], crops["bgr8"])
        mono = crops["mono8"]
        assert np.array_equal(mono[:, :, 0], mono[:, :, 1]), "a grey image gives a grey crop"
        for encoding, crop in crops.items():
            score = marker_board.crop_similarity(crop, expected[name])
            assert score >= marker_board.SAME_CROP_THRESHOLD, f"{name} from {encoding}: {score:.3f}"


@pytest.mark.slow
def test_an_unknown_dictionary_is_refused_with_the_choices(built_ws, domain_id):
    use_interfaces(built_ws)
    from readmarker.marker_reader import MarkerReader

    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    try:
        with pytest.raises(ValueError, match="DICT_4X4_50"):
            MarkerReader(context=context, parameter_overrides=[Parameter("dictionary", value="DICT_9X9")])
    finally:
        rclpy.try_shutdown(context=context)


# ---- the packages, built and run ------------------------------------------------------------

def test_packages_have_the_ament_python_layout():
    for package in PACKAGES:
        root = SOURCE / package
        manifest = ElementTree.parse(root / "package.xml").getroot()
        assert manifest.get("format") == "3"
        assert manifest.findtext("name") == package
        assert manifest.findtext("export/build_type") == "ament_python"
        depends = {element.text for element in manifest.findall("depend")}
        assert {"rclpy", "sensor_msgs"} <= depends
        assert (root / "resource" / package).is_file()
        assert (root / package / "__init__.py").is_file()
        assert f"install_scripts=$base/lib/{package}" in (root / "setup.cfg").read_text()


@pytest.fixture(scope="module")
def built_ws(tmp_path_factory):
    """The catdog_warp packages (sources only) in a temporary workspace, built as the grader builds
    them (the interface package from a cache), once."""
    from autograder.builds import reference, workspace_build

    folder = tmp_path_factory.mktemp("reference")
    ws = reference.write_reference_workspace("catdog_warp", folder)
    report = workspace_build.build_here("catdog_warp", folder)
    assert report.ok, report.reason
    return ws


class Pipeline:
    """webcam image_publisher and readmarker marker_reader running, and a test node listening."""

    def __init__(self):
        self.camera = self.reader = self.context = None
        self.crops = {name: [] for name in marker_board.PICTURES}
        self.input_stamps = set()

    def start(self, ws, domain_id):
        self.camera = workspace.run(ws, "webcam", "image_publisher", params={"rate": 10.0, "seed": 3},
                                    domain_id=domain_id)
        self.reader = workspace.run(ws, "readmarker", "marker_reader", domain_id=domain_id)
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=domain_id)
        self.node = Node("pipeline_tester", context=self.context)
        self.node.create_subscription(Image, "image", lambda msg: self.input_stamps.add(stamp_of(msg)), 100)
        use_interfaces(ws)
        from catdog_interfaces.msg import CroppedPicture

        self.node.create_subscription(CroppedPicture, "cropped_img",
                                      lambda msg: self.crops[PICTURE_NAMES[msg.picture]].append(msg.image), 100)
        self.bad_publisher = self.node.create_publisher(Image, "image", 10)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def spin_until(self, condition, timeout=WAIT, every=None):
        for process in (self.camera, self.reader):
            assert process.running(), f"{process.name} ended ({process.describe_exit()}):\n{process.log_tail()}"
        return spin_until(self.executor, condition, timeout, every)

    def close(self):
        if self.context is not None:
            self.executor.shutdown()
            self.node.destroy_node()
            rclpy.try_shutdown(context=self.context)
        for process in (self.camera, self.reader):
            if process is not None:
                process.stop()


@pytest.fixture(scope="module")
def pipeline(built_ws):
    with rosenv.reserve_domain_id() as reservation:
        running = Pipeline()
        try:
            running.start(built_ws, reservation.domain_id)
            yield running
        finally:
            running.close()


@pytest.mark.slow
def test_colcon_installs_both_executables(built_ws):
    assert workspace.executables(built_ws, "webcam") == ["image_publisher"]
    assert workspace.executables(built_ws, "readmarker") == ["marker_reader"]


@pytest.mark.slow
def test_built_nodes_deliver_png_crops_stamped_like_their_frames(pipeline):
    def stamped_crops(name):
        return [msg for msg in pipeline.crops[name] if stamp_of(msg) in pipeline.input_stamps]

    assert pipeline.spin_until(lambda: all(len(stamped_crops(name)) >= 3 for name in marker_board.PICTURES)), (
        f"crops received: { {n: len(m) for n, m in pipeline.crops.items()} }, frames: {len(pipeline.input_stamps)}"
        f"\nmarker_reader log:\n{pipeline.reader.log_tail()}")
    first_frame = min(pipeline.input_stamps)
    for name, messages in pipeline.crops.items():
        for msg in messages:
            if stamp_of(msg) >= first_frame:  # crops of frames sent before we listened are not checked
                assert stamp_of(msg) in pipeline.input_stamps, f"{name}: a crop with a stamp no frame had"
        assert "png" in messages[-1].format
        crop = images.compressed_to_image(messages[-1])
        assert crop.shape == (240, 320, 3) and crop.dtype == np.uint8
        # The simulated camera films the drawn board: the crop shows the drawn picture.
        drawn = pictures.draw_cat() if name == "cat" else pictures.draw_dog()
        assert marker_board.crop_similarity(crop, drawn) >= marker_board.SAME_CROP_THRESHOLD


@pytest.mark.slow
def test_built_marker_reader_logs_a_malformed_image_and_keeps_running(pipeline):
    malformed = Image(height=480, width=640, encoding="bgr8", step=1920, data=bytes(1000))
    malformed.header.stamp.sec = 1  # no real frame has this stamp
    assert pipeline.spin_until(lambda: "Skipping an image" in pipeline.reader.log,
                               every=lambda: pipeline.bad_publisher.publish(malformed)), (
        f"no warning about the malformed image; marker_reader log:\n{pipeline.reader.log_tail()}")
    assert "1000 bytes" in pipeline.reader.log
    before = max(stamp_of(msg) for msg in pipeline.crops["cat"]) if pipeline.crops["cat"] else (0, 0)
    assert pipeline.spin_until(lambda: any(stamp_of(msg) > before for msg in pipeline.crops["cat"])), (
        f"no crops after the malformed image; marker_reader log:\n{pipeline.reader.log_tail()}")
    assert pipeline.reader.running()


@pytest.mark.slow
def test_built_nodes_stop_cleanly_on_ctrl_c(pipeline):
    # 60 s: a backstop before SIGKILL (stop's own 5 s would make a slow exit on a busy machine fail)
    assert pipeline.camera.stop(timeout=60) == 0, pipeline.camera.log_tail()
    assert pipeline.reader.stop(timeout=60) == 0, pipeline.reader.log_tail()
    assert "Traceback" not in pipeline.reader.log + pipeline.camera.log


# ---- every assignment's reference packages ------------------------------------------------------

@pytest.mark.parametrize("assignment", sorted(name for name, spec in assignments.ASSIGNMENTS.items() if spec.packages))
def test_the_source_notebook_writes_exactly_the_reference_packages(tmp_path, assignment):
    """The source notebook's cells write exactly the files of the assignment's reference packages
    (markers removed), and its solution cells are the files with solution regions."""
    from autograder.builds import reference

    files = reference.reference_files(assignment)
    assert set(assignments.spec(assignment).packages) == {name.split("/")[2] for name in files}
    nb = reference.source_notebook(assignment)
    reference.write_files(nb, tmp_path)
    written = {str(p.relative_to(tmp_path)): p.read_text() for p in tmp_path.rglob("*") if p.is_file()}
    assert written == files
    solutions = [c for c in reference.writefile_cells(nb) if c.metadata.get("nbgrader", {}).get("solution")]
    assert solutions and all("### BEGIN SOLUTION" in c.source for c in solutions)
