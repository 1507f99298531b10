# SPDX-License-Identifier: Apache-2.0
"""Converts a EuRoC-layout folder into a ROS bag with PyPI `rosbags`, a writer independent of ours.

    python write_bag.py SEQUENCE OUT [--storage ros1|sqlite3|mcap] [--encoding ENCODING]
        [--compression none|bz2|lz4] [--camera-info] [--imu-late] [--imu-csv FILE]
        [--row-padding N] [--empty]

SEQUENCE holds mav0/cam0/data.csv with its PNGs (8-bit gray or colour, as `inertialnet synth`
writes them), mav0/cam0/sensor.yaml and mav0/imu0/data.csv. OUT is a ROS 1 .bag (--storage
ros1, --compression for its chunks) or a rosbag2 folder (sqlite3 or mcap). Topics:
  /cam0/image_raw             sensor_msgs/Image (or /cam0/image_raw/compressed, CompressedImage)
  /cam0/camera_info           sensor_msgs/CameraInfo, once per frame (--camera-info)
  /imu0                       sensor_msgs/Imu, every row of imu0/data.csv
Header stamps are the CSVs' timestamps; the log (receive) times are 1 ms later, so a reader that
took them for the stamps would be caught. --encoding writes the frames losslessly as
  mono8, mono16 (value·257: /257 gives the 8-bit value back), mono16-be (is_bigendian = 1),
  rgb8, bgr8, rgba8, bgra8 (gray in every colour channel, alpha 255), 8UC1, 8UC3,
  compressed-png (the PNG file's own bytes, format "mono8; png compressed"),
  bayer_rggb8 (gray bytes labelled as a Bayer pattern: readers must refuse it).
There is no JPEG encoder in the test environment: JPEG CompressedImages are tested in
tests/io/test_ros1_bags.cpp with OpenCV's encoder.
--row-padding N: N bytes of padding after every row (step > width · bytes per pixel).
--imu-late: IMU messages start at the third frame's stamp (the IMU started after the camera);
--imu-csv FILE writes the IMU rows the bag holds in EuRoC's CSV, for the `--imu FILE` path.
--empty: the connections are declared and no message is written.
"""
import argparse
import re
import shutil
import struct
import zlib
from pathlib import Path

import numpy as np
from rosbags.typesys import Stores, get_typestore

RECEIVE_DELAY_NS = 1_000_000


def read_png(path):
    """8-bit gray/gray+alpha/RGB/RGBA non-interlaced PNG → uint8 array (H, W[, C])."""
    data = path.read_bytes()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', path
    at, idat = 8, b''
    while at < len(data):
        (length,) = struct.unpack('>I', data[at:at + 4])
        kind = data[at + 4:at + 8]
        body = data[at + 8:at + 8 + length]
        if kind == b'IHDR':
            width, height, depth, colour, _, _, interlace = struct.unpack('>IIBBBBB', body)
            assert depth == 8 and interlace == 0, f'{path}: only 8-bit non-interlaced PNGs'
        elif kind == b'IDAT':
            idat += body
        elif kind == b'IEND':
            break
        at += 12 + length
    channels = {0: 1, 4: 2, 2: 3, 6: 4}[colour]
    raw = zlib.decompress(idat)
    stride = width * channels
    out = np.zeros((height, stride), dtype=np.uint8)
    previous = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, row = line[0], np.frombuffer(line[1:], dtype=np.uint8).astype(np.int32)
        rec = np.zeros(stride, dtype=np.int32)
        for x in range(stride):
            a = rec[x - channels] if x >= channels else 0
            b = previous[x]
            c = previous[x - channels] if x >= channels else 0
            if kind == 0:
                p = 0
            elif kind == 1:
                p = a
            elif kind == 2:
                p = b
            elif kind == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            rec[x] = (row[x] + p) & 0xFF
        out[y] = rec
        previous = rec
    return out.reshape(height, width, channels) if channels > 1 else out


def gray_of(pixels):
    if pixels.ndim == 2:
        return pixels
    assert pixels.shape[2] in (1, 3, 4) and np.all(pixels[..., 0] == pixels[..., 1]), 'colour frames: gray ones only'
    return pixels[..., 0]


def raw_frame(gray, encoding, padding):
    """(ROS encoding, is_bigendian, bytes per pixel row without padding, row bytes) for a gray frame."""
    if encoding in ('mono8', '8UC1', 'bayer_rggb8'):
        rows, name, big = gray, encoding, 0
    elif encoding in ('mono16', 'mono16-be'):
        values = gray.astype(np.uint16) * 257
        big = 1 if encoding == 'mono16-be' else 0
        rows = values.astype('>u2' if big else '<u2').view(np.uint8).reshape(gray.shape[0], -1)
        name = 'mono16'
    elif encoding in ('rgb8', 'bgr8', '8UC3'):
        rows, name, big = np.repeat(gray[..., None], 3, axis=2).reshape(gray.shape[0], -1), encoding, 0
    elif encoding in ('rgba8', 'bgra8'):
        alpha = np.full(gray.shape + (1,), 255, dtype=np.uint8)
        rows = np.concatenate([np.repeat(gray[..., None], 3, axis=2), alpha], axis=2).reshape(gray.shape[0], -1)
        name, big = encoding, 0
    else:
        raise SystemExit(f'write_bag.py: unknown encoding {encoding}')
    padded = np.concatenate([rows, np.zeros((rows.shape[0], padding), dtype=np.uint8)], axis=1)
    return name, big, padded.shape[1], padded.reshape(-1)


def read_sensor_yaml(path):
    text = path.read_text()

    def numbers(key):
        found = re.search(key + r':\s*\[([^\]]*)\]', text)
        return [float(v) for v in found.group(1).split(',')] if found else []

    model = re.search(r'distortion_model:\s*(\S+)', text)
    return {'resolution': [int(v) for v in numbers('resolution')], 'intrinsics': numbers('intrinsics'),
            'distortion_model': model.group(1) if model else 'radial-tangential',
            'distortion': numbers('distortion_coefficients')}


def read_csv(path):
    rows = []
    for line in path.read_text().splitlines():
        if line.strip() and not line.startswith('#'):
            rows.append([v.strip() for v in line.split(',')])
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('sequence', type=Path)
    parser.add_argument('out', type=Path)
    parser.add_argument('--storage', choices=['ros1', 'sqlite3', 'mcap'], default='ros1')
    parser.add_argument('--encoding', default='mono8')
    parser.add_argument('--compression', choices=['none', 'bz2', 'lz4'], default='none')
    parser.add_argument('--camera-info', action='store_true')
    parser.add_argument('--imu-late', action='store_true')
    parser.add_argument('--imu-csv', type=Path)
    parser.add_argument('--row-padding', type=int, default=0)
    parser.add_argument('--empty', action='store_true')
    args = parser.parse_args()

    ros1 = args.storage == 'ros1'
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    prefix = 'sensor_msgs/msg/'
    Header = ts.types['std_msgs/msg/Header']
    Time = ts.types['builtin_interfaces/msg/Time']
    Image = ts.types[prefix + 'Image']
    CompressedImage = ts.types[prefix + 'CompressedImage']
    Imu = ts.types[prefix + 'Imu']
    CameraInfo = ts.types[prefix + 'CameraInfo']
    RegionOfInterest = ts.types[prefix + 'RegionOfInterest']
    Quaternion = ts.types['geometry_msgs/msg/Quaternion']
    Vector3 = ts.types['geometry_msgs/msg/Vector3']

    def header(stamp, frame, seq):
        t = Time(sec=stamp // 1_000_000_000, nanosec=stamp % 1_000_000_000)
        return Header(seq=seq, stamp=t, frame_id=frame) if ros1 else Header(stamp=t, frame_id=frame)

    def serialize(message, msgtype):
        return ts.serialize_ros1(message, msgtype) if ros1 else ts.serialize_cdr(message, msgtype)

    mav0 = args.sequence / 'mav0'
    frames = [(int(t), mav0 / 'cam0' / 'data' / name) for t, name in read_csv(mav0 / 'cam0' / 'data.csv')]
    imu_rows = [[int(r[0])] + [float(v) for v in r[1:7]] for r in read_csv(mav0 / 'imu0' / 'data.csv')]
    if args.imu_late:
        imu_rows = [r for r in imu_rows if r[0] >= frames[2][0]]
    if args.imu_csv:
        lines = ['#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],'
                 'a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]']
        lines += [','.join([str(r[0])] + [repr(v) for v in r[1:]]) for r in imu_rows]
        args.imu_csv.write_text('\n'.join(lines) + '\n')
    sensor = read_sensor_yaml(mav0 / 'cam0' / 'sensor.yaml')

    compressed = args.encoding.startswith('compressed-')
    image_topic = '/cam0/image_raw/compressed' if compressed else '/cam0/image_raw'
    image_type = prefix + ('CompressedImage' if compressed else 'Image')
    messages = []  # (log time, topic, message type, message)
    for seq, (stamp, path) in enumerate(frames):
        if compressed:
            if args.encoding != 'compressed-png':
                raise SystemExit(f'write_bag.py: {args.encoding}: only compressed-png can be written here')
            message = CompressedImage(header=header(stamp, 'cam0', seq), format='mono8; png compressed',
                                      data=np.frombuffer(path.read_bytes(), dtype=np.uint8))
        else:
            gray = gray_of(read_png(path))
            name, big, step, data = raw_frame(gray, args.encoding, args.row_padding)
            message = Image(header=header(stamp, 'cam0', seq), height=gray.shape[0], width=gray.shape[1], encoding=name,
                            is_bigendian=big, step=step, data=data)
        messages.append((stamp + RECEIVE_DELAY_NS, image_topic, image_type, message))
        if args.camera_info:
            fx, fy, cx, cy = sensor['intrinsics']
            if sensor['distortion_model'] == 'equidistant':
                model, d = 'equidistant', sensor['distortion']
            else:
                model, d = 'plumb_bob', (sensor['distortion'] + [0.0] * 5)[:5]
            k = np.array([fx, 0, cx, 0, fy, cy, 0, 0, 1], dtype=np.float64)
            p = np.array([fx, 0, cx, 0, 0, fy, cy, 0, 0, 0, 1, 0], dtype=np.float64)
            info = CameraInfo(header=header(stamp, 'cam0', seq), height=sensor['resolution'][1],
                              width=sensor['resolution'][0], distortion_model=model,
                              D=np.array(d, dtype=np.float64), K=k, R=np.eye(3).reshape(-1), P=p, binning_x=0,
                              binning_y=0, roi=RegionOfInterest(x_offset=0, y_offset=0, height=0, width=0,
                                                                do_rectify=False)) if ros1 else \
                CameraInfo(header=header(stamp, 'cam0', seq), height=sensor['resolution'][1],
                           width=sensor['resolution'][0], distortion_model=model, d=np.array(d, dtype=np.float64),
                           k=k, r=np.eye(3).reshape(-1), p=p, binning_x=0, binning_y=0,
                           roi=RegionOfInterest(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False))
            messages.append((stamp + RECEIVE_DELAY_NS, '/cam0/camera_info', prefix + 'CameraInfo', info))
    zeros = np.zeros(9, dtype=np.float64)
    for seq, row in enumerate(imu_rows):
        message = Imu(header=header(row[0], 'imu0', seq), orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                      orientation_covariance=zeros, angular_velocity=Vector3(x=row[1], y=row[2], z=row[3]),
                      angular_velocity_covariance=zeros,
                      linear_acceleration=Vector3(x=row[4], y=row[5], z=row[6]),
                      linear_acceleration_covariance=zeros)
        messages.append((row[0] + RECEIVE_DELAY_NS, '/imu0', prefix + 'Imu', message))
    messages.sort(key=lambda m: m[0])  # a recorder writes in receive order
    if args.empty:
        messages = []

    topics = [(image_topic, image_type), ('/imu0', prefix + 'Imu')]
    if args.camera_info:
        topics.append(('/cam0/camera_info', prefix + 'CameraInfo'))
    if args.out.exists():
        shutil.rmtree(args.out) if args.out.is_dir() else args.out.unlink()
    if ros1:
        from rosbags.rosbag1 import Writer
        writer = Writer(args.out)
        if args.compression != 'none':
            writer.set_compression(Writer.CompressionFormat[args.compression.upper()])
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer
        plugin = StoragePlugin.MCAP if args.storage == 'mcap' else StoragePlugin.SQLITE3
        writer = Writer(args.out, version=9, storage_plugin=plugin)
    writer.open()
    # rosbags names types sensor_msgs/msg/X; a ROS 1 bag stores them as sensor_msgs/X.
    connections = {topic: writer.add_connection(topic, msgtype, typestore=ts) for topic, msgtype in topics}
    for log_time, topic, msgtype, message in messages:
        writer.write(connections[topic], log_time, serialize(message, msgtype))
    writer.close()


if __name__ == '__main__':
    main()
