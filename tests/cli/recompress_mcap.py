# SPDX-License-Identifier: Apache-2.0
"""Rewrites an MCAP file with other chunk compression, through PyPI `mcap` (independent of ours).

    python recompress_mcap.py IN.mcap OUT.mcap --compression none|zstd|lz4

`rosbags` (tests/support/write_bag.py) writes MCAP bags uncompressed or with zstd chunks and no
chunk CRCs; `mcap` writes zstd and LZ4-frame chunks with CRCs, the way rosbag2's own MCAP
storage plugin does. The schemas, channels and messages (log and publish times, sequence
numbers, bytes) are copied in their stored order; small chunks so that the messages span several.
"""
import argparse

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

parser = argparse.ArgumentParser()
parser.add_argument('input')
parser.add_argument('output')
parser.add_argument('--compression', choices=['none', 'zstd', 'lz4'], required=True)
args = parser.parse_args()

with open(args.input, 'rb') as source, open(args.output, 'wb') as target:
    reader = make_reader(source)
    header = reader.get_header()
    writer = Writer(target, chunk_size=64 * 1024, compression=CompressionType[args.compression.upper()],
                    enable_crcs=True)
    writer.start(profile=header.profile, library='recompress_mcap.py')
    schemas, channels = {}, {}
    for schema, channel, message in reader.iter_messages(log_time_order=False):
        if schema is not None and schema.id not in schemas:
            schemas[schema.id] = writer.register_schema(name=schema.name, encoding=schema.encoding, data=schema.data)
        if channel.id not in channels:
            channels[channel.id] = writer.register_channel(
                topic=channel.topic, message_encoding=channel.message_encoding,
                schema_id=schemas[schema.id] if schema is not None else 0, metadata=channel.metadata)
        writer.add_message(channel_id=channels[channel.id], log_time=message.log_time,
                           publish_time=message.publish_time, data=message.data, sequence=message.sequence)
    writer.finish()
