"""rosbag2 bags as ROS 2 Jazzy writes and reads them: a folder with ``metadata.yaml`` and an MCAP
file (Jazzy's default storage), what the course's ``ros2 bag`` records, prints and plays.

    bag = bag_files.BagWriter("my_bag")        # my_bag/my_bag_0.mcap, metadata.yaml at close()
    bag.add_topic("/chatter", "std_msgs/msg/String", offered_qos_profiles=[...], type_hash="RIHS01_...")
    bag.write("/chatter", serialized_bytes, log_time=ns, publish_time=ns)
    bag.close()
    print(bag_metadata.format_info(bag_files.read_metadata("my_bag")))   # `ros2 bag info my_bag`

The layout is rosbag2's (Jazzy): metadata.yaml as course_lib.ros.bag_metadata writes it, the
MCAP file with the "ros2" profile, one ``ros2msg`` schema per type (the .msg file followed by
the definitions it uses, as rosbag2_cpp's LocalMessageDefinitionSource writes it), one ``cdr``
channel per topic (metadata ``offered_qos_profiles`` and ``topic_type_hash``), chunks without
compression, and a "rosbag2" metadata record; a full ROS install's ``ros2 bag info/play`` reads
it. Reading takes versions 4-9 of metadata.yaml and single ``.mcap`` files. The MCAP records
are the ``mcap`` package's (PyPI).
"""

from __future__ import annotations

import os
import re
import struct
import sys
import time
from pathlib import Path

from course_lib.ros.bag_metadata import (
    METADATA_FILE,
    NO_START,
    BagMetadata,
    TopicInformation,
    from_dict,
    metadata_yaml,
    offered_profiles,
    yaml_lines,
)

#: The storage this module writes and plays (Jazzy's default); ``-s`` names it.
STORAGE_ID = "mcap"
#: rosbag2's MCAP chunk size (the mcap C++ library's default): 768 KiB.
CHUNK_SIZE = 768 * 1024


class BagError(RuntimeError):
    """A bag that cannot be read or written; str() is rosbag2's words where it has them."""


# --- message definitions -----------------------------------------------------------------------

_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")
_PRIMITIVES = {"bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
               "uint32", "int64", "uint64", "string"}
_SEPARATOR = "=" * 80 + "\n"


def message_definition(type_name: str) -> str:
    """The ``ros2msg`` schema of a message type, as rosbag2 stores it in MCAP: the type's .msg
    file, then each type it uses (once, depth first, in sorted order) after a line of 80 "="
    and ``MSG: pkg/Type``; names and order as rosbag2_cpp's LocalMessageDefinitionSource.

    Raises:
        LookupError: the type's package or .msg file is not installed (the message says which).
    """
    from course_lib.ros import interfaces

    seen: set[str] = set()

    def text_of(name: str) -> str:
        package, _, base = name.partition("/")
        base = base.rpartition("/")[2]
        text = interfaces.definition_path(f"{package}/msg/{base}").read_text(encoding="utf-8")
        used = set()
        for match in _FIELD_TYPE.finditer(text):
            field_type = match.group(1)
            if field_type not in _PRIMITIVES:
                used.add(field_type if "/" in field_type else f"{package}/{field_type}")
        for dependency in sorted(used):
            if dependency not in seen:
                seen.add(dependency)
                text += f"\n{_SEPARATOR}MSG: {dependency}\n" + text_of(dependency)
        return text

    return text_of(type_name)


def read_metadata(path) -> BagMetadata:
    """A bag's metadata as ``ros2 bag info`` reads it: a bag folder's metadata.yaml, or the
    summary of a single .mcap file; ``bag_size`` is the size of the folder's files (or the file's).

    Raises:
        BagError: in rosbag2_cpp's words: no such path, a folder without metadata.yaml, a
            metadata.yaml that does not parse, a file that is no MCAP.
    """
    import yaml

    path = Path(path)
    if not path.exists():
        raise BagError(f"Bag path {path} does not exist.")
    if path.is_dir():
        metadata_file = path / METADATA_FILE
        if not metadata_file.is_file():
            raise BagError(f"Could not find metadata in bag directory {path}")
        try:
            fields = yaml.safe_load(metadata_file.read_text(encoding="utf-8"))["rosbag2_bagfile_information"]
            metadata = from_dict(fields)
        except (yaml.YAMLError, KeyError, TypeError, ValueError) as error:
            raise BagError(f"Exception on parsing info file: {error!r}") from None
        metadata.bag_size = sum(item.stat().st_size for item in path.iterdir() if item.is_file())
        return metadata
    metadata = _mcap_metadata(path)
    if metadata is None:
        log_error("rosbag2_storage", "No storage id specified, and no plugin found that could open URI")
        raise BagError(f"No plugin detected that could open file {path}")
    return metadata


def _mcap_metadata(path: Path) -> BagMetadata | None:
    """A single MCAP file's metadata from its summary, as rosbag2's MCAP storage reads it; None
    when the file is no MCAP with a summary (a recording that was killed needs ``ros2 bag reindex``)."""
    import yaml
    from mcap.exceptions import McapError
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as stream:
            reader = make_reader(stream)
            summary = reader.get_summary()
            if summary is None or summary.statistics is None:
                return None
            distro = ""
            for record in reader.iter_metadata():
                if record.name == "rosbag2":  # Jazzy's bags say it here, older ones in ROS_DISTRO
                    serialized = yaml.safe_load(record.metadata.get("serialized_metadata") or "{}") or {}
                    distro = serialized.get("ros_distro") or record.metadata.get("ROS_DISTRO", "")
    except (McapError, OSError, ValueError, EOFError, struct.error, yaml.YAMLError):
        return None
    stats = summary.statistics
    topics = [TopicInformation(
        name=channel.topic, type=summary.schemas[channel.schema_id].name, serialization_format=channel.message_encoding,
        offered_qos_profiles=offered_profiles(channel.metadata.get("offered_qos_profiles", "")),
        type_description_hash=channel.metadata.get("topic_type_hash", ""),
        message_count=stats.channel_message_counts.get(channel_id, 0))
        for channel_id, channel in summary.channels.items()]
    return BagMetadata(storage_identifier=STORAGE_ID, relative_file_paths=[str(path)],
                       duration=stats.message_end_time - stats.message_start_time,
                       starting_time=stats.message_start_time, message_count=stats.message_count, topics=topics,
                       ros_distro=distro, bag_size=path.stat().st_size)


def log_error(logger: str, text: str) -> None:
    """An error line as rcutils prints it ([ERROR] [seconds.nanoseconds] [logger]: text)."""
    now = time.time_ns()
    print(f"[ERROR] [{now // 10**9}.{now % 10**9:09d}] [{logger}]: {text}", file=sys.stderr)


# --- writing -----------------------------------------------------------------------------------

class BagWriter:
    """Writes a bag the way rosbag2's SequentialWriter with the MCAP storage does (one file).

    Args:
        folder: the bag folder to create; it must not exist yet.
        ros_distro: metadata's ros_distro (ROS_DISTRO, or the course's Jazzy).

    Raises:
        BagError: the folder exists (ros2bag's words) or cannot be made.
    """

    def __init__(self, folder, ros_distro: str | None = None):
        from mcap.writer import CompressionType, Writer

        from course_lib.ros import rosenv

        self.folder = Path(folder)
        if self.folder.is_dir():
            raise BagError(f"Output folder '{folder}' already exists.")
        try:
            os.makedirs(self.folder)
        except OSError:
            raise BagError(f"Could not create bag folder '{folder}'.") from None
        self.file_name = f"{self.folder.resolve().name}_0.{STORAGE_ID}"
        self._stream = open(self.folder / self.file_name, "wb")
        self._mcap = Writer(self._stream, chunk_size=CHUNK_SIZE, compression=CompressionType.NONE)
        self._mcap.start(profile="ros2", library="course_lib.ros.bag_files")
        self.ros_distro = ros_distro or os.environ.get("ROS_DISTRO") or rosenv.DISTRO
        self.topics: dict[str, TopicInformation] = {}
        self._channels: dict[str, int] = {}
        self._schemas: dict[str, int] = {}
        self.start = NO_START
        self.end = None
        self.closed = False

    def add_topic(self, name: str, type_name: str, offered_qos_profiles: list[dict], type_hash: str = "",
                  definition: str | None = None) -> None:
        """Add a topic (a channel, and its type's schema the first time); again: nothing.

        Args:
            offered_qos_profiles: the publishers' profiles, as qos_to_dict gives them.
            definition: the ros2msg schema; None reads it from the installed .msg files, and
                "" stores none (encoding "unknown", as rosbag2 does for a type it cannot find).
        """
        if name in self.topics:
            return
        if type_name not in self._schemas:
            text = message_definition(type_name) if definition is None else definition
            self._schemas[type_name] = self._mcap.register_schema(
                type_name, "ros2msg" if text else "unknown", text.encode())
        profiles = "\n".join(yaml_lines(offered_qos_profiles, 0)) if offered_qos_profiles else "[]"
        self._channels[name] = self._mcap.register_channel(
            name, "cdr", self._schemas[type_name],
            {"offered_qos_profiles": profiles, "topic_type_hash": type_hash})
        self.topics[name] = TopicInformation(name, type_name, list(offered_qos_profiles), type_hash)

    def write(self, topic: str, data: bytes, log_time: int, publish_time: int) -> None:
        """Write one serialized message: ``log_time`` is when it was received (ns since the
        epoch, the bag's clock), ``publish_time`` when it was sent."""
        self._mcap.add_message(self._channels[topic], log_time=log_time, data=data, publish_time=publish_time)
        self.topics[topic].message_count += 1
        self.start = min(self.start, log_time)
        self.end = log_time if self.end is None else max(self.end, log_time)

    def metadata(self) -> BagMetadata:
        """The metadata so far, as close() writes it."""
        topics = list(self.topics.values())
        return BagMetadata(
            storage_identifier=STORAGE_ID, relative_file_paths=[self.file_name],
            duration=0 if self.end is None else self.end - self.start, starting_time=self.start,
            message_count=sum(topic.message_count for topic in topics), topics=topics, ros_distro=self.ros_distro)

    def close(self) -> BagMetadata:
        """Finish the MCAP file (summary, "rosbag2" metadata record) and write metadata.yaml."""
        if self.closed:
            return self.metadata()
        self.closed = True
        metadata = self.metadata()
        self._mcap.add_metadata("rosbag2", {"serialized_metadata": metadata_yaml(metadata, top_key=False)})
        self._mcap.finish()
        self._stream.close()
        (self.folder / METADATA_FILE).write_text(metadata_yaml(metadata), encoding="utf-8")
        return metadata


# --- reading -----------------------------------------------------------------------------------

def storage_files(path) -> list[Path]:
    """The storage files of a bag folder (from its metadata) or the .mcap file itself.

    Raises:
        BagError: rosbag2's "No storage could be initialized from the inputs." for anything
            that is not an MCAP bag (after its storage factory's error line, as rosbag2 logs it).
    """
    path = Path(path)
    if path.is_dir() and (path / METADATA_FILE).is_file():
        metadata = read_metadata(path)
        if metadata.storage_identifier != STORAGE_ID:
            raise BagError(f"The bag's storage is '{metadata.storage_identifier}': the course's ros2 bag "
                           f"plays {STORAGE_ID} bags only (Jazzy's default); a full ROS 2 install plays the others")
        return [path / name for name in metadata.relative_file_paths]
    if path.is_file() and _mcap_metadata(path) is not None:
        return [path]
    log_error("rosbag2_storage", "No storage id specified, and no plugin found that could open URI")
    raise BagError("No storage could be initialized from the inputs.")


def read_messages(files: list[Path], topics=None):
    """(topic, serialized bytes, log_time) of each message of the files, in the order of their
    log times within each file; only the ``topics`` given, when given."""
    from mcap.reader import make_reader

    for file in files:
        with open(file, "rb") as stream:
            for _, channel, message in make_reader(stream).iter_messages(topics=topics, log_time_order=True):
                yield channel.topic, message.data, message.log_time
