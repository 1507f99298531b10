# SPDX-License-Identifier: Apache-2.0
"""Writes the small ROS 2 bags that test_ros2_bags reads, with writers independent of ours.

    python write_ros2_bags.py OUT_FOLDER

`rosbags` writes rosbag2 folders (sqlite3 in schema versions 8 and 9; MCAP plain and zstd, which
it writes without chunk CRCs); PyPI `mcap` writes MCAP files with lz4 and zstd chunks and their
CRCs, small chunks so that messages span several. Every bag holds the same messages, written in
log-time order: sensor_msgs Image, Imu and CameraInfo serialised by `rosbags` (CDR; ROS 1 for
the "ros1" MCAP). expected.json lists the topics, types, counts and each message's log time and
bytes, which the test compares with what our readers return. Damaged files and folders are made
from the good ones.
"""
import json
import shutil
import sqlite3
import sys
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

out = Path(sys.argv[1])
shutil.rmtree(out, ignore_errors=True)
out.mkdir(parents=True)

ts = get_typestore(Stores.ROS2_HUMBLE)
Time = ts.types['builtin_interfaces/msg/Time']
Header = ts.types['std_msgs/msg/Header']
Image = ts.types['sensor_msgs/msg/Image']
Imu = ts.types['sensor_msgs/msg/Imu']
CameraInfo = ts.types['sensor_msgs/msg/CameraInfo']
RegionOfInterest = ts.types['sensor_msgs/msg/RegionOfInterest']
Quaternion = ts.types['geometry_msgs/msg/Quaternion']
Vector3 = ts.types['geometry_msgs/msg/Vector3']

T0 = 1_700_000_000_000_000_000
RECEIVE_DELAY = 1_000_000  # log times 1 ms after the header stamps, so the two cannot be confused


def header(stamp, frame):
    return Header(stamp=Time(sec=stamp // 1_000_000_000, nanosec=stamp % 1_000_000_000), frame_id=frame)


def image(i, stamp):
    pixels = (np.arange(12, dtype=np.uint8) * (i + 1)).astype(np.uint8)
    return Image(header=header(stamp, 'cam0'), height=3, width=4, encoding='mono8', is_bigendian=0, step=4,
                 data=pixels)


def imu(i, stamp):
    zeros = np.zeros(9, dtype=np.float64)
    return Imu(header=header(stamp, 'imu0'), orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
               orientation_covariance=zeros, angular_velocity=Vector3(x=0.01 * i, y=-0.02 * i, z=0.5),
               angular_velocity_covariance=zeros, linear_acceleration=Vector3(x=0.0, y=0.0, z=9.81),
               linear_acceleration_covariance=zeros)


def camera_info(stamp):
    return CameraInfo(header=header(stamp, 'cam0'), height=3, width=4, distortion_model='plumb_bob',
                      d=np.array([0.1, -0.01, 0.0, 0.0, 0.0]), k=np.array([5.0, 0, 2, 0, 5.0, 1.5, 0, 0, 1]),
                      r=np.eye(3).flatten(), p=np.array([5.0, 0, 2, 0, 0, 5.0, 1.5, 0, 0, 0, 1, 0]),
                      binning_x=0, binning_y=0,
                      roi=RegionOfInterest(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False))


TOPICS = {'/cam0/image_raw': 'sensor_msgs/msg/Image', '/imu0': 'sensor_msgs/msg/Imu',
          '/cam0/camera_info': 'sensor_msgs/msg/CameraInfo'}

# (topic, log time, message) in log-time order: 3 images at 20 Hz, 11 IMU samples at 200 Hz from
# before the first image, one CameraInfo.
messages = [('/cam0/camera_info', T0 + RECEIVE_DELAY, camera_info(T0))]
messages += [('/imu0', T0 + i * 5_000_000 + RECEIVE_DELAY, imu(i, T0 + i * 5_000_000)) for i in range(11)]
messages += [('/cam0/image_raw', T0 + i * 50_000_000 + RECEIVE_DELAY + 1, image(i, T0 + i * 50_000_000))
             for i in range(3)]
messages.sort(key=lambda m: m[1])


def cdr(topic, message):
    return bytes(ts.serialize_cdr(message, TOPICS[topic]))


def ros1(topic, message):
    return bytes(ts.serialize_ros1(message, TOPICS[topic]))


def write_rosbag2(folder, storage, version=9, zstd=False, compression_mode=CompressionMode.STORAGE):
    writer = Writer(out / folder, version=version, storage_plugin=storage)
    if zstd:
        writer.set_compression(compression_mode, CompressionFormat.ZSTD)  # before open()
    with writer:
        connections = {topic: writer.add_connection(topic, TOPICS[topic], typestore=ts) for topic in TOPICS}
        for topic, time, message in messages:
            writer.write(connections[topic], time, cdr(topic, message))


def write_mcap(name, compression, encoding='cdr', serialize=cdr):
    with open(out / name, 'wb') as stream:
        writer = McapWriter(stream, chunk_size=600, compression=compression, enable_crcs=True)
        writer.start(profile='ros2' if encoding == 'cdr' else 'ros1', library='write_ros2_bags.py')
        channels = {}
        for topic, msgtype in TOPICS.items():
            msgdef, _ = ts.generate_msgdef(msgtype, ros_version=2 if encoding == 'cdr' else 1)
            schema = writer.register_schema(name=msgtype, encoding='ros2msg' if encoding == 'cdr' else 'ros1msg',
                                            data=msgdef.encode())
            channels[topic] = writer.register_channel(topic=topic, message_encoding=encoding, schema_id=schema)
        for sequence, (topic, time, message) in enumerate(messages):
            writer.add_message(channel_id=channels[topic], log_time=time, publish_time=time,
                               data=serialize(topic, message), sequence=sequence)
        writer.finish()


write_rosbag2('sqlite_v9', StoragePlugin.SQLITE3, version=9)
write_rosbag2('sqlite_v8', StoragePlugin.SQLITE3, version=8)
write_rosbag2('mcap_plain', StoragePlugin.MCAP)
write_rosbag2('mcap_zstd', StoragePlugin.MCAP, zstd=True)
# rosbag2's per-message compression: each message a zstd frame (refused, named).
write_rosbag2('sqlite_message_zstd', StoragePlugin.SQLITE3, zstd=True, compression_mode=CompressionMode.MESSAGE)
write_rosbag2('mcap_message_zstd', StoragePlugin.MCAP, zstd=True, compression_mode=CompressionMode.MESSAGE)
write_mcap('lz4.mcap', CompressionType.LZ4)
write_mcap('zstd_crc.mcap', CompressionType.ZSTD)
write_mcap('plain_crc.mcap', CompressionType.NONE)
write_mcap('ros1.mcap', CompressionType.NONE, encoding='ros1', serialize=ros1)

# A channel in an encoding that is not ROS: refused by name.
with open(out / 'json.mcap', 'wb') as stream:
    writer = McapWriter(stream, compression=CompressionType.NONE)
    writer.start(profile='', library='write_ros2_bags.py')
    schema = writer.register_schema(name='Point', encoding='jsonschema', data=b'{}')
    channel = writer.register_channel(topic='/points', message_encoding='json', schema_id=schema)
    writer.add_message(channel_id=channel, log_time=T0, publish_time=T0, data=b'{"x": 1}')
    writer.finish()

# Damaged databases: rosbag2's messages table missing; the file cut to its first half.
shutil.copy(out / 'sqlite_v9' / 'sqlite_v9.db3', out / 'no_messages.db3')
with sqlite3.connect(out / 'no_messages.db3') as db:
    db.execute('DROP TABLE messages')
db.close()
data = (out / 'sqlite_v9' / 'sqlite_v9.db3').read_bytes()
(out / 'truncated.db3').write_bytes(data[:len(data) // 2])

# A folder with metadata.yaml as rosbag2 itself (yaml-cpp, Humble) writes it: sequences indented
# below their key, the QoS profiles one double-quoted string with escapes.
humble = out / 'humble_folder'
humble.mkdir()
shutil.copy(out / 'sqlite_v8' / 'sqlite_v8.db3', humble / 'humble_folder_0.db3')
qos = ('"- history: 3\\n  depth: 0\\n  reliability: 1\\n  durability: 2\\n  deadline:\\n    sec: 9223372036\\n'
       '    nsec: 854775807\\n  lifespan:\\n    sec: 9223372036\\n    nsec: 854775807\\n  liveliness: 1\\n'
       '  liveliness_lease_duration:\\n    sec: 9223372036\\n    nsec: 854775807\\n'
       '  avoid_ros_namespace_conventions: false"')
topics_yaml = ''.join(f"""    - topic_metadata:
        name: {topic}
        type: {msgtype}
        serialization_format: cdr
        offered_qos_profiles: {qos}
      message_count: {sum(1 for m in messages if m[0] == topic)}
""" for topic, msgtype in TOPICS.items())
(humble / 'metadata.yaml').write_text(f"""rosbag2_bagfile_information:
  version: 5
  storage_identifier: sqlite3
  duration:
    nanoseconds: 101000001
  starting_time:
    nanoseconds_since_epoch: {T0 + RECEIVE_DELAY}
  message_count: {len(messages)}
  topics_with_message_count:
{topics_yaml}  compression_format: ""
  compression_mode: ""
  relative_file_paths:
    - humble_folder_0.db3
  files:
    - path: humble_folder_0.db3
      starting_time:
        nanoseconds_since_epoch: {T0 + RECEIVE_DELAY}
      duration:
        nanoseconds: 101000001
      message_count: {len(messages)}
""")

# Folders refused: a bag split into two files; rosbag2's file compression; no metadata.yaml.
metadata = (out / 'sqlite_v9' / 'metadata.yaml').read_text()
split = out / 'split_folder'
shutil.copytree(out / 'sqlite_v9', split)
(split / 'metadata.yaml').write_text(metadata.replace('  - sqlite_v9.db3\n', '  - sqlite_v9.db3\n  - sqlite_v9_1.db3\n'))
compressed = out / 'compressed_folder'
shutil.copytree(out / 'sqlite_v9', compressed)
(compressed / 'metadata.yaml').write_text(metadata.replace("compression_mode: ''", 'compression_mode: FILE'))
(out / 'no_metadata_folder').mkdir()

expected = {
    'topics': {topic: {'type': msgtype, 'count': sum(1 for m in messages if m[0] == topic)}
               for topic, msgtype in TOPICS.items()},
    'messages': [{'topic': topic, 'log_time': time, 'cdr': cdr(topic, message).hex(),
                  'ros1': ros1(topic, message).hex()} for topic, time, message in messages],
}
(out / 'expected.json').write_text(json.dumps(expected, indent=1))
