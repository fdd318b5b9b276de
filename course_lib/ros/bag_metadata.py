"""What a rosbag2 bag's metadata.yaml says (rosbag2_storage::BagMetadata, version 9 as ROS 2
Jazzy writes it) and how ``ros2 bag info`` prints it; course_lib.ros.bag_files writes and reads the
bags.

Version 9 holds each topic's offered QoS profiles as a YAML list with the policies by name
("reliable", "transient_local"); versions 4-8 held a YAML text with rmw's enum numbers, which
reading takes too. The text is laid out as yaml-cpp lays out rosbag2's (sequences indented
under their key, "" and ~ for empty values).
"""

from __future__ import annotations

import dataclasses
import json
import re
import time

#: The metadata.yaml version rosbag2 writes on Jazzy.
METADATA_VERSION = 9
METADATA_FILE = "metadata.yaml"
#: The starting time of a bag without messages (rosbag2 leaves its initial maximum there).
NO_START = 2**63 - 1
#: rmw's infinite duration, as offered QoS profiles of Jazzy's endpoints carry it.
INFINITE = {"sec": 9223372036, "nsec": 854775807}
#: How rosbag2 < 9 wrote the policies: rmw's enum numbers (rclpy's enums have the same values).
_POLICY_NUMBERS = {"history": ("system_default", "keep_last", "keep_all", "unknown"),
                   "reliability": ("system_default", "reliable", "best_effort", "unknown", "best_available"),
                   "durability": ("system_default", "transient_local", "volatile", "unknown", "best_available"),
                   "liveliness": ("system_default", "automatic", "manual_by_node", "manual_by_topic", "unknown",
                                  "best_available")}


@dataclasses.dataclass
class TopicInformation:
    """One topic of a bag: rosbag2's topic_metadata and its message_count."""

    name: str
    type: str
    offered_qos_profiles: list[dict]
    type_description_hash: str = ""
    serialization_format: str = "cdr"
    message_count: int = 0


@dataclasses.dataclass
class BagMetadata:
    """What metadata.yaml holds (rosbag2_storage::BagMetadata), and the bag's size on disk."""

    storage_identifier: str
    relative_file_paths: list[str]
    duration: int  # nanoseconds
    starting_time: int  # nanoseconds since the epoch
    message_count: int
    topics: list[TopicInformation]
    ros_distro: str = ""
    version: int = METADATA_VERSION
    compression_format: str = ""
    compression_mode: str = ""
    custom_data: dict = dataclasses.field(default_factory=dict)
    bag_size: int = 0

    def to_dict(self) -> dict:
        """The fields in rosbag2's order (yaml.hpp), one file as the course writes them."""
        topics = [{"topic_metadata": {"name": t.name, "type": t.type, "serialization_format": t.serialization_format,
                                      "offered_qos_profiles": t.offered_qos_profiles,
                                      "type_description_hash": t.type_description_hash},
                   "message_count": t.message_count} for t in self.topics]
        files = [{"path": path, "starting_time": {"nanoseconds_since_epoch": self.starting_time},
                  "duration": {"nanoseconds": self.duration}, "message_count": self.message_count}
                 for path in self.relative_file_paths]
        return {"version": self.version, "storage_identifier": self.storage_identifier,
                "duration": {"nanoseconds": self.duration},
                "starting_time": {"nanoseconds_since_epoch": self.starting_time},
                "message_count": self.message_count, "topics_with_message_count": topics,
                "compression_format": self.compression_format, "compression_mode": self.compression_mode,
                "relative_file_paths": self.relative_file_paths, "files": files,
                "custom_data": self.custom_data or None, "ros_distro": self.ros_distro}


# --- offered QoS profiles ---------------------------------------------------------------------

def qos_to_dict(profile) -> dict:
    """An rclpy QoSProfile (as get_publishers_info_by_topic gives it) as metadata.yaml version 9
    holds it: policies by rmw's names ("reliable", "unknown"), durations as {sec, nsec}."""
    def duration(value) -> dict:
        nanoseconds = value.nanoseconds
        return {"sec": nanoseconds // 10**9, "nsec": nanoseconds % 10**9}

    return {"history": profile.history.name.lower(), "depth": int(profile.depth),
            "reliability": profile.reliability.name.lower(), "durability": profile.durability.name.lower(),
            "deadline": duration(profile.deadline), "lifespan": duration(profile.lifespan),
            "liveliness": profile.liveliness.name.lower(),
            "liveliness_lease_duration": duration(profile.liveliness_lease_duration),
            "avoid_ros_namespace_conventions": bool(profile.avoid_ros_namespace_conventions)}


def _policy_names(profile: dict) -> dict:
    """A profile of any metadata version with its policies as names (version 9's form)."""
    named = dict(profile)
    for field, names in _POLICY_NUMBERS.items():
        value = named.get(field)
        if isinstance(value, int) and 0 <= value < len(names):
            named[field] = names[value]
    return named


def offered_profiles(value) -> list[dict]:
    """offered_qos_profiles of metadata.yaml or of an MCAP channel: a list (version 9), a YAML
    text of one (versions 4-8, and channels), or nothing."""
    import yaml

    if isinstance(value, str):
        value = yaml.safe_load(value) if value.strip() else []
    return [_policy_names(profile) for profile in value or []]


# --- metadata.yaml -----------------------------------------------------------------------------

_PLAIN = re.compile(r"[A-Za-z0-9_/.\-]+")


def _scalar(value) -> str:
    if value is None:
        return "~"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    text = str(value)
    plain = _PLAIN.fullmatch(text) and not re.fullmatch(r"[-+.\d].*|true|false|null|~|yes|no|on|off", text, re.I)
    return text if plain else json.dumps(text)


def yaml_lines(value, indent: int) -> list[str]:
    """Block YAML laid out as yaml-cpp emits rosbag2's metadata (sequences indented under their key)."""
    pad = " " * indent
    lines = []
    if isinstance(value, dict):
        for key, item in value.items():
            if isinstance(item, (dict, list)) and item:
                lines.append(f"{pad}{key}:")
                lines += yaml_lines(item, indent + 2)
            else:
                lines.append(f"{pad}{key}: {'[]' if item == [] else '{}' if item == {} else _scalar(item)}")
    else:
        for item in value:
            inner = yaml_lines(item, indent + 2) if isinstance(item, (dict, list)) else [pad + "  " + _scalar(item)]
            lines.append(f"{pad}- {inner[0].lstrip()}")
            lines += inner[1:]
    return lines


def metadata_yaml(metadata: BagMetadata, top_key: bool = True) -> str:
    """metadata.yaml's text (``top_key``), or the serialized_metadata of the MCAP's "rosbag2" record."""
    fields = metadata.to_dict()
    return "\n".join(yaml_lines({"rosbag2_bagfile_information": fields} if top_key else fields, 0)) + "\n"


def from_dict(fields: dict) -> BagMetadata:
    """The metadata of metadata.yaml's rosbag2_bagfile_information (versions 4-9).

    Raises:
        KeyError, TypeError, ValueError: a field is missing or not what rosbag2 writes.
    """
    topics = []
    for entry in fields.get("topics_with_message_count") or []:
        topic = entry["topic_metadata"]
        topics.append(TopicInformation(
            name=topic["name"], type=topic["type"], serialization_format=topic.get("serialization_format", "cdr"),
            offered_qos_profiles=offered_profiles(topic.get("offered_qos_profiles")),
            type_description_hash=topic.get("type_description_hash") or "",
            message_count=int(entry.get("message_count", 0))))
    return BagMetadata(
        version=int(fields["version"]), storage_identifier=fields["storage_identifier"],
        relative_file_paths=list(fields.get("relative_file_paths") or []),
        duration=int(fields["duration"]["nanoseconds"]),
        starting_time=int(fields["starting_time"]["nanoseconds_since_epoch"]),
        message_count=int(fields["message_count"]), topics=topics, ros_distro=fields.get("ros_distro") or "",
        compression_format=fields.get("compression_format") or "",
        compression_mode=fields.get("compression_mode") or "",
        custom_data=dict(fields.get("custom_data") or {}))


# --- ros2 bag info -----------------------------------------------------------------------------

def _size(size: int) -> str:
    """rosbag2's bag size: B, then KiB, MiB, GiB, TiB with one decimal."""
    units = ("B", "KiB", "MiB", "GiB", "TiB")
    value, index = float(size), 0
    while value >= 1024 and index < len(units) - 1:
        value /= 1024
        index += 1
    return f"{value:.0f} {units[0]}" if index == 0 else f"{value:.1f} {units[index]}"


def _seconds(nanoseconds: int) -> str:
    return f"{nanoseconds // 10**9}.{nanoseconds % 10**9:09d}"


def _time_point(nanoseconds: int) -> str:
    local = time.localtime(nanoseconds // 10**9)
    return (f"{time.strftime('%b %e %Y', local)} {time.strftime('%H:%M:%S', local)}.{nanoseconds % 10**9:09d} "
            f"({_seconds(nanoseconds)})")


def is_service_event(topic: TopicInformation) -> bool:
    return "/srv/" in topic.type and topic.type.endswith("_Event") and topic.name.endswith("/_service_event")


def format_info(metadata: BagMetadata) -> str:
    """A bag's metadata as ``ros2 bag info`` prints it on Jazzy (rosbag2_py's format_bag_meta_data):
    a blank line, then fields aligned at column 19; service event topics are counted apart."""
    pad = " " * 19
    topics = [topic for topic in metadata.topics if not is_service_event(topic)]
    services = [topic for topic in metadata.topics if is_service_event(topic)]
    service_messages = sum(topic.message_count for topic in services)
    lines = ["", "Files:             " + f"\n{pad}".join(metadata.relative_file_paths),
             f"Bag size:          {_size(metadata.bag_size)}",
             f"Storage id:        {metadata.storage_identifier}",
             f"ROS Distro:        {metadata.ros_distro or 'unknown'}",
             f"Duration:          {_seconds(metadata.duration)}s",
             f"Start:             {_time_point(metadata.starting_time)}",
             f"End:               {_time_point(metadata.starting_time + metadata.duration)}",
             f"Messages:          {metadata.message_count - service_messages}",
             "Topic information: " + f"\n{pad}".join(
                 f"Topic: {t.name} | Type: {t.type} | Count: {t.message_count} | "
                 f"Serialization Format: {t.serialization_format}" for t in topics),
             f"Service:           {len(services)}",
             "Service information: " + f"\n{pad}  ".join(
                 f"Service: {t.name[:-len('/_service_event')]} | Type: {t.type[:-len('_Event')]} | "
                 f"Event Count: {t.message_count} | Serialization Format: {t.serialization_format}"
                 for t in services)]
    return "\n".join(lines) + ("\n" if services else "")
