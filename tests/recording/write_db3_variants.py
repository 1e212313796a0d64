#!/usr/bin/env python3
"""Writes the sqlite3 twins of ros2_variants.cjs's MCAP files with Python's sqlite3, from its dump.json and
dump.bin in DIR (the export's topics and messages, and the topics a replay skips). Usage: write_db3_variants.py DIR
  humble.db3: Humble's tables (no message_definitions), the export's topics alone: the schema-free reference;
  jazzy.db3:  Jazzy's (schema version 4: topics with type_description_hash, message_definitions holding the
              ros2msg texts of jazzy.mcap);
  skip.db3:   jazzy.db3 plus the skipped topics as sqlite3 has them: serialization_format json or protobuf in
              `topics`, message_definitions rows with encoding ros2idl, jsonschema, protobuf, or unknown with an
              empty text (what rosbag2 writes when it finds no definition), a .srv text, one that does not parse."""
import json
import os
import sqlite3
import struct
import sys


def read_dump(folder):
    topics = json.load(open(os.path.join(folder, "dump.json")))
    data = open(os.path.join(folder, "dump.bin"), "rb").read()
    messages, at = [], 0
    while at < len(data):
        index, log_time, size = struct.unpack_from("<HQI", data, at)
        at += 14
        messages.append((index, log_time, data[at:at + size]))
        at += size
    return topics, messages


def write(path, topics, messages, distro, with_skipped):
    if os.path.exists(path):
        os.remove(path)
    db = sqlite3.connect(path)
    jazzy = distro == "jazzy"
    db.execute("CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)")
    db.execute("INSERT INTO schema VALUES (?, ?)", (4 if jazzy else 3, distro))
    db.execute("CREATE TABLE metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL)")
    db.execute("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
               "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL%s)" %
               (", type_description_hash TEXT NOT NULL" if jazzy else ""))
    db.execute("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
               "data BLOB NOT NULL)")
    if jazzy:
        db.execute("CREATE TABLE message_definitions(id INTEGER PRIMARY KEY, topic_type TEXT NOT NULL, "
                   "encoding TEXT NOT NULL, encoded_message_definition TEXT NOT NULL, "
                   "type_description_hash TEXT NOT NULL)")
    kept = [i for i, t in enumerate(topics) if with_skipped or not t["skipped"]]
    defined = set()
    for i in kept:
        t = topics[i]
        row = (i + 1, t["topic"], t["type"], t["messageEncoding"], t["qos"])
        db.execute("INSERT INTO topics VALUES (?, ?, ?, ?, ?%s)" % (", ''" if jazzy else ""), row)
        if jazzy and t["type"] not in defined:
            defined.add(t["type"])
            db.execute("INSERT INTO message_definitions (topic_type, encoding, encoded_message_definition, "
                       "type_description_hash) VALUES (?, ?, ?, '')",
                       (t["type"], t["schemaEncoding"] or "unknown", t["schema"]))
    keep = set(kept)
    db.executemany("INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)",
                   [(i + 1, log_time, data) for i, log_time, data in messages if i in keep])
    db.commit()
    db.close()


def main():
    folder = sys.argv[1]
    topics, messages = read_dump(folder)
    write(os.path.join(folder, "humble.db3"), topics, messages, "humble", False)
    write(os.path.join(folder, "jazzy.db3"), topics, messages, "jazzy", False)
    write(os.path.join(folder, "skip.db3"), topics, messages, "jazzy", True)


if __name__ == "__main__":
    main()
