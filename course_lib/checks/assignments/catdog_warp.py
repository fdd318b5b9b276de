"""The catdog_warp assignment: its spec, its notebook's words and its checks (``crop_pictures`` and
``MarkerReader``, on generated scenes).

The contract is the notebook's introduction (CATDOG_WARP_INTRO); the board convention is
course_lib.imaging.marker_board's. Crops are compared with the ground truth of the generated scene
(Scene.expected_crops) by marker_board.crop_similarity, passing at marker_board.SAME_CROP_THRESHOLD;
colours are checked separately (crop_similarity compares grey levels, so a red/blue swap would pass it).
"""

from __future__ import annotations

import re
import time

from course_lib.checks import packages
from course_lib.checks.context import Context, clip, scaled
from course_lib.checks.registry import check
from course_lib.checks.spec import Assignment, NotebookText

# --- the notebook's words (markdown) and the spec ----------------------------------------

CATDOG_WARP_INTRO = """
# Assignment: cat and dog, warped upright

A camera looks at the course's marker board: a cat picture framed by ArUco markers 1-4 and a dog
picture framed by markers 5-8 (dictionary `DICT_4X4_50`), in the order top-left, top-right,
bottom-right, bottom-left. Each marker touches its picture with one corner: marker 1 with its
corner 2, marker 2 with corner 3, marker 3 with corner 0, marker 4 with corner 1
(`course_lib.imaging.marker_board.PICTURES` and `CORNER_OF_MARKER`; OpenCV numbers a marker's corners
clockwise from its top-left).

**Contract** (this is exactly what is graded). Your workspace `ros2_ws/src` holds three packages:

1. **`catdog_interfaces`**: the message `msg/CroppedPicture.msg` with `int32 picture` (constants
   `CAT=1`, `DOG=2`) and `sensor_msgs/CompressedImage image`.
2. **`webcam`**: the executable **`image_publisher`** (given: the course's simulated board, a video
   file or a real camera on `image`).
3. **`readmarker`**:
   - `readmarker/crop.py`: `crop_pictures(frame_bgr, size=(320, 240)) -> dict`, `{"cat": crop,
     "dog": crop}` with a key **only when all four markers** of that picture are found; each crop is
     a BGR `uint8` image of `size` = (width, height), upright and not mirrored (the picture's
     top-left corner at pixel (0, 0));
   - `readmarker/marker_reader.py`: the node **`marker_reader`** (executable `marker_reader`);
     subscribes **`image`** (`sensor_msgs/msg/Image`) and for every frame publishes each crop it
     finds on **`cropped_img`** as a `CroppedPicture` (`picture` 1 for the cat, 2 for the dog; the
     crop as a PNG, `images.image_to_compressed(crop, "png")`);
   - `launch/catdog_warp.launch.xml`, starting `image_publisher` and `marker_reader`
     (`ros2 launch readmarker catdog_warp.launch.xml`); `package.xml` declares every ROS package the
     code imports.

The grader renders scenes (`course_lib.imaging.scenes.render_scene`) with poses and lighting you have not
seen, and compares your crops with the true ones (`marker_board.crop_similarity`, passing at
`marker_board.SAME_CROP_THRESHOLD`). Try your function on `scenes.render_scene(seed).frame`.
"""

#: The spec: what assignments/build.py, the grader and the checks below read about it.
SPEC = Assignment("catdog_warp", "03", {"catdog_interfaces": (), "webcam": ("image_publisher",),
                           "readmarker": ("marker_reader",)},
           NotebookText(intro=CATDOG_WARP_INTRO, plain_ros=(
               "In plain ROS 2 the packages come from `ros2 pkg create` (`--build-type ament_cmake` for "
               "`catdog_interfaces`, `ament_python` for the others)."),
               checks={"easy": ("easy views",), "hard": ("hard views",), "missing_and_none": ("missing markers",),
                       "noisy": ("noise, blur, another size",), "node": ("the node",)},
               imports="from course_lib import marker_board, scenes\n", names="crop_pictures",
               try_text="Try it on a generated scene (this cell is yours to change):", try_code="""
scene = scenes.render_scene(1)
try:
    print(sorted(crop_pictures(scene.frame)))   # ['cat', 'dog']
except NotImplementedError:  # the stub: Run All goes on to the checks, which say what is missing
    print("Not done yet: crop_pictures still raises NotImplementedError. Write it in the crop.py "
          "cell above, run that cell and the import cell, then this one.")
"""),
           functions=("readmarker", "readmarker.crop"))
selfcheck, grade = SPEC.selfcheck, SPEC.grade  # what the notebook calls: checks.selfcheck("...")

INTERFACES, _WEBCAM, PACKAGE = SPEC.packages
#: The message of a crop: which picture (CAT = 1, DOG = 2) and the crop.
MESSAGE_FIELDS = [("int32", "picture"), ("sensor_msgs/CompressedImage", "image")]
PICTURE_NUMBERS = {"cat": 1, "dog": 2}
SIZE = (320, 240)
#: Largest difference of the per-channel means of a crop and its expected crop (grey levels).
COLOUR_TOLERANCE = 20.0


def _seed(ctx) -> int:
    return int(ctx.rng.integers(0, 2**31))


def compare_crop(ctx, label: str, crop, expected, show: bool = False) -> bool:
    """One item: the student's crop is the expected picture (shape, dtype, content, colours)."""
    import numpy as np

    from course_lib.imaging import marker_board

    if not isinstance(crop, np.ndarray):
        return ctx.item(False, f"{label}: the crop is a {type(crop).__name__}, not a numpy image")
    want = (SIZE[1], SIZE[0], 3) if expected is None else expected.shape
    if crop.shape != want or crop.dtype != np.uint8:
        hint = " (size is (width, height): warpPerspective(frame, H, size))" if crop.shape[:2] == want[1::-1] else ""
        return ctx.item(False, f"{label}: crop has shape {crop.shape} {crop.dtype}, expected {want} uint8{hint}")
    similarity = marker_board.crop_similarity(crop, expected)
    if show:
        ctx.image(f"{label}: yours ({similarity:.2f})", crop)
        ctx.image(f"{label}: expected", expected)
    if similarity < marker_board.SAME_CROP_THRESHOLD:
        hints = []
        for name, variant in (("mirrored left-right", crop[:, ::-1]), ("upside down", crop[::-1, ::-1]),
                              ("flipped top-bottom", crop[::-1])):
            if marker_board.crop_similarity(variant, expected) >= marker_board.SAME_CROP_THRESHOLD:
                hints.append(f"it is the expected picture {name}: check the order of the four corners "
                             "(top-left, top-right, bottom-right, bottom-left) on both sides of the warp")
        return ctx.item(False, f"{label}: similarity {similarity:.2f} < {marker_board.SAME_CROP_THRESHOLD}"
                               + (f"; {hints[0]}" if hints else ""))
    mine, theirs = crop.reshape(-1, 3).mean(axis=0), expected.reshape(-1, 3).mean(axis=0)
    if np.abs(mine - theirs).max() > COLOUR_TOLERANCE:
        swapped = np.abs(mine[::-1] - theirs).max() <= COLOUR_TOLERANCE
        return ctx.item(False, f"{label}: the right picture in the wrong colours" +
                        ("; red and blue are swapped: OpenCV images are BGR, keep them BGR" if swapped else ""))
    return ctx.item(True, f"{label}: matches (similarity {similarity:.2f})")


def _check_scene(ctx, label: str, scene, outcome, show: bool = False) -> None:
    from course_lib.imaging import marker_board

    if not outcome.ok:
        stub = outcome.error.startswith("NotImplementedError")
        hint = " (replace `raise NotImplementedError()` with your code)" if stub else ""
        ctx.item(False, f"{label}: crop_pictures failed: {outcome.error}{hint}")
        return
    result = outcome.value
    if not isinstance(result, dict):
        ctx.item(False, f"{label}: crop_pictures returned a {outcome.pytype}, not a dict like {{'cat': crop}}")
        return
    unknown = sorted(set(result) - set(marker_board.PICTURES))
    if unknown:
        ctx.item(False, f"{label}: unexpected keys {unknown}; the keys are 'cat' and 'dog'")
    expected = scene.expected_crops(SIZE) if scene is not None else {}
    framed = scene.fully_framed if scene is not None else ()
    visible = set(scene.visible_ids) if scene is not None else set()
    for name, markers in marker_board.PICTURES.items():
        if name in framed:
            if name not in result:
                ctx.item(False, f"{label}: no '{name}' although its markers {markers} are all in view")
            else:
                compare_crop(ctx, f"{label}, {name}", result[name], expected[name], show=show)
        elif not visible.issuperset(markers):
            missing = sorted(set(markers) - visible)
            ok = name not in result
            ctx.item(ok, f"{label}: no '{name}' (markers {missing} are not in view)" if ok else
                     f"{label}: returned '{name}' although markers {missing} are not in view: add a key "
                     "only when all four of its markers were detected")


def _run_scenes(ctx, cases, show_first: bool = True) -> None:
    outcomes = ctx.call("crop_pictures", [((scene.frame,), {"size": list(SIZE)}) for _, scene in cases],
                        labels=[f"'{label}'" for label, _ in cases])
    for index, ((label, scene), outcome) in enumerate(zip(cases, outcomes, strict=True)):
        _check_scene(ctx, label, scene, outcome, show=show_first and index == 0)


@check(points=3, timeout=60)
def easy(ctx: Context) -> None:
    """crop_pictures finds and warps both pictures on easy (mildly tilted) views."""
    from course_lib.imaging import scenes

    _run_scenes(ctx, [(f"easy scene {i + 1}", scenes.render_scene(_seed(ctx), difficulty="easy")) for i in range(3)])


@check(points=2, timeout=60)
def hard(ctx: Context) -> None:
    """crop_pictures on hard views: steep, rotated, partly off-frame; only fully framed pictures."""
    from course_lib.imaging import scenes

    cases = []
    for _attempt in range(40):  # two scenes that show a whole picture, then one of any kind
        seed = _seed(ctx)
        if len(cases) < 2 and not scenes.framed_from(scenes.scene_pose(seed, difficulty="hard")):
            continue  # no picture can be whole in view: drawing the scene would be wasted
        scene = scenes.render_scene(seed, difficulty="hard")
        if scene.fully_framed or len(cases) >= 2:
            cases.append((f"hard scene {len(cases) + 1}", scene))
        if len(cases) == 3:
            break
    _run_scenes(ctx, cases)


@check(points=2, timeout=60)
def missing_and_none(ctx: Context) -> None:
    """A picture with any one of its markers missing is left out; frames without markers give an empty dict."""
    import numpy as np

    from course_lib.imaging import marker_board, scenes

    # Every marker is the missing one once, in every grading: scene k lacks the k-th marker of
    # each picture (so a solution that looks at only some of a picture's markers always loses).
    cases = []
    for k in range(4):
        gone = [ids[k] for ids in marker_board.PICTURES.values()]
        cases.append((f"markers {gone} missing",
                      scenes.render_scene(_seed(ctx), difficulty="easy", missing_markers=gone)))
    cases.append(("no markers on the board", scenes.render_scene(_seed(ctx), difficulty="easy",
                                                                 missing_markers=list(range(1, 9)))))
    noise = ctx.rng.integers(0, 256, size=(480, 640, 3), dtype=np.uint8)
    outcomes = ctx.call("crop_pictures", [((scene.frame,), {"size": list(SIZE)}) for _, scene in cases]
                        + [((noise,), {"size": list(SIZE)})], labels=[f"'{label}'" for label, _ in cases] + ["noise"])
    for (label, scene), outcome in zip(cases, outcomes[:-1], strict=True):
        _check_scene(ctx, label, scene, outcome)
    outcome = outcomes[-1]
    ok = outcome.ok and outcome.value == {}
    got = sorted(outcome.value) if outcome.ok and isinstance(outcome.value, dict) else outcome.value
    ctx.item(ok, "noise: returns {}" if ok else "noise: expected {}, got " +
             (outcome.error if not outcome.ok else f"keys {got}"))


@check(points=1, timeout=60)
def noisy(ctx: Context) -> None:
    """crop_pictures copes with sensor noise, blur and JPEG artefacts, and with another crop size."""
    import numpy as np

    from course_lib.imaging import camera_views, scenes

    pose = scenes.scene_pose(_seed(ctx), difficulty="easy")
    look = camera_views.Look(noise=7.0, blur=1.0, jpeg_quality=60, gain=0.9)
    scene = scenes.render_scene(_seed(ctx), difficulty="easy", pose=pose, look=look)
    small = (200, 150)
    outcomes = ctx.call("crop_pictures", [((scene.frame,), {"size": list(SIZE)}),
                                          ((scene.frame,), {"size": list(small)})],
                        labels=["a noisy, blurred scene", f"a noisy, blurred scene at size={small}"])
    _check_scene(ctx, "noisy, blurred scene", scene, outcomes[0])
    if outcomes[1].ok and isinstance(outcomes[1].value, dict) and "cat" in outcomes[1].value:
        crop = outcomes[1].value["cat"]
        ok = isinstance(crop, np.ndarray) and crop.shape == (small[1], small[0], 3)
        ctx.item(ok, f"size={small}: the crop is {small[0]}x{small[1]}" if ok else
                 f"size={small}: crop shape {getattr(crop, 'shape', None)}, expected {(small[1], small[0], 3)}; "
                 "use the size argument, (width, height)")
    else:
        ctx.item(False, f"size={small}: no 'cat' crop ({outcomes[1].error or 'missing key'})")


@check(points=3, timeout=90)
def node(ctx: Context) -> None:
    """marker_reader: node marker_reader turns frames on image into CroppedPicture messages on cropped_img."""
    from concurrent.futures import ThreadPoolExecutor

    proc = packages.run(ctx, PACKAGE, SPEC.executable(PACKAGE))  # ros2 run readmarker marker_reader
    packages.use_interfaces(ctx)
    from catdog_interfaces.msg import CroppedPicture

    packages.message_item(ctx, INTERFACES, "CroppedPicture", MESSAGE_FIELDS)
    packages.dependency_items(ctx, PACKAGE)
    # The launch file's nodes run at the same time, in a ROS domain of their own: its
    # marker_reader must not answer this node's frames, nor this node its camera's.
    with ThreadPoolExecutor(1) as pool:
        launched = pool.submit(_launch_item, ctx, CroppedPicture)
        try:
            node_ran = _single_node_items(ctx, proc, CroppedPicture)
        finally:
            ok, message = launched.result()
    if node_ran:  # a node that does not run says it all
        ctx.item(ok, message)


def _single_node_items(ctx: Context, proc, message_type) -> bool:
    """The items of ``ros2 run readmarker marker_reader`` (`proc`), fed a drawn frame: a cat and
    a dog crop arrive on cropped_img, each the expected picture. False when the node did not run."""
    from rclpy.qos import QoSProfile, ReliabilityPolicy
    from sensor_msgs.msg import Image

    from course_lib.imaging import images, scenes

    try:
        with ctx.probe() as probe:
            got: dict[str, list] = {"cat": [], "dog": []}
            # Reliable publisher and best-effort subscriptions match every QoS the student may pick.
            pub = probe.node.create_publisher(Image, "image",
                                              QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE))
            numbers = {number: name for name, number in PICTURE_NUMBERS.items()}
            probe.node.create_subscription(
                message_type, "cropped_img",
                lambda msg: got[numbers[msg.picture]].append(msg.image) if msg.picture in numbers else None,
                QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
            names = lambda: {n for n, _ in probe.node.get_node_names_and_namespaces()}  # noqa: E731
            # The frame is drawn while the node's process starts (it takes about a second).
            scene = scenes.render_scene(_seed(ctx), difficulty="easy")
            expected = scene.expected_crops(SIZE)
            msg = images.image_to_msg(scene.frame, "bgr8")
            ctx.wait_for_node(probe, proc, "marker_reader")
            if not proc.running():
                ctx.item(False, f"the node process ended ({proc.describe_exit()}):\n{clip(proc.log_tail(6))}")
                return False
            running = "marker_reader" in names()
            if not ctx.precondition(running, "node marker_reader runs" if running else
                                    f"no node named marker_reader (nodes: {sorted(names())})"):
                return False
            gave_up = ctx.no_answer_coming(proc, 8.0)
            probe.resend_until(pub, msg, lambda: bool(got["cat"] and got["dog"]) or not proc.running() or gave_up(),
                               scaled(8.0), every=0.5)
            types = dict(probe.node.get_topic_names_and_types())
    finally:
        proc.stop(timeout=2)
    wanted = ["catdog_interfaces/msg/CroppedPicture"]
    for name in ("cat", "dog"):
        topic = f"/cropped_img ({name}, picture {PICTURE_NUMBERS[name]})"
        if not got[name]:
            seen = types.get("/cropped_img")
            ctx.item(False, f"no {name} (picture = {PICTURE_NUMBERS[name]}) arrived on /cropped_img" +
                     (f" (it carries {seen}; the contract says {wanted[0]})" if seen and seen != wanted else
                      "" if seen else
                      f" (topics: {sorted(t for t in types if not t.startswith(('/rosout', '/parameter')))})") +
                     "; the node's output:\n" + clip(proc.log_tail(4)))
            continue
        try:
            crop = images.compressed_to_image(got[name][-1], want="bgr8")
        except Exception as error:  # what the student sent is not a decodable image
            ctx.item(False, f"{topic}: the message does not decode ({error}); "
                            "use images.image_to_compressed(crop, 'png')")
            continue
        compare_crop(ctx, topic, crop, expected[name], show=True)
    return True


#: The launch file that starts the camera and the marker reader.
LAUNCH = (PACKAGE, "catdog_warp.launch.xml")


def _ended(launch, node: str) -> bool:
    """True once the launch has said that its process `node` ended, as ros2 launch says it
    ("[marker_reader-2]: process has died [...]" or "... has finished cleanly"): the launch goes on
    with its other processes, and no crop can come any more."""
    return re.search(rf"\[{node}-\d+\]: process has (died|finished cleanly)", launch.log) is not None


def _launch_item(ctx: Context, message_type) -> tuple[bool, str]:
    """One item, (ok, message): ``ros2 launch readmarker catdog_warp.launch.xml`` starts
    image_publisher and marker_reader, and crops of the camera's board arrive on cropped_img (the
    webcam's default camera is the course's simulated board); in ctx.second_domain_id."""
    import sys

    from rclpy.qos import QoSProfile, ReliabilityPolicy

    ws = packages.require_build(ctx)
    domain_id = ctx.second_domain_id
    command = [sys.executable, "-m", "course_lib.launch", *LAUNCH]
    launch = ctx.students.start(command, name="student-launch", cwd=ctx.workdir, domain_id=domain_id,
                                wall_seconds=ctx.remaining() + 5, env=packages.student_env(ctx, ws))
    crops = []
    backstop = min(scaled(20.0), ctx.remaining() - 3)
    try:
        with ctx.probe(domain_id) as probe:
            probe.node.create_subscription(message_type, "cropped_img", crops.append,
                                           QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT))
            # Its marker_reader may compute or wait for ever (crop_pictures hangs): judged like the
            # single node's, from when it shows.
            reader: dict = {}

            def reader_gave_up() -> bool:
                if "gave_up" in reader:
                    return reader["gave_up"]()
                if "marker_reader" in {n for n, _ in probe.node.get_node_names_and_namespaces()}:
                    member = launch.member("marker_reader")
                    if member is not None:
                        reader["gave_up"] = ctx.no_answer_coming(member, 8.0)
                return "gave_up" in reader and reader["gave_up"]()

            started = time.monotonic()
            probe.spin_until(lambda: bool(crops) or not launch.running() or _ended(launch, "marker_reader")
                             or reader_gave_up(), backstop)
            waited = time.monotonic() - started
            nodes = {n for n, _ in probe.node.get_node_names_and_namespaces()}
    finally:
        launch.stop(timeout=3)
    shown = f"`ros2 launch {' '.join(LAUNCH)}`"
    if crops:
        return True, f"{shown} starts image_publisher and marker_reader; crops arrive on /cropped_img"
    missing = sorted({"image_publisher", "marker_reader"} - nodes)
    return False, (f"{shown}: no crop arrived on /cropped_img in {waited:.0f} s"
                   + (f"; nodes missing: {missing}" if missing else "")
                   + f". Its output:\n{clip(launch.log_tail(6))}")
