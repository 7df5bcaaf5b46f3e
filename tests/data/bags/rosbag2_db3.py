"""rosbag2 sqlite3 storage (ROS 2 Humble layout) writer and reader with Python's sqlite3.

Layout as rosbag2_storage_default_plugins' SqliteStorage (Humble) creates it: tables
  schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL)        -- one row (3, 'humble')
  metadata(id INTEGER PRIMARY KEY, metadata_version INTEGER NOT NULL, metadata TEXT NOT NULL)
  topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,
         serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)
  messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL)
  index timestamp_idx ON messages (timestamp ASC)
messages.timestamp is the receive time in ns since the epoch; data is the CDR payload with its
4-byte encapsulation header. Beside the .db3, metadata.yaml (rosbag2_bagfile_information, version 5)
lists the topics, counts, times and relative_file_paths.
"""
import os
import sqlite3

SCHEMA_SQL = [
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);",
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,metadata TEXT NOT NULL);",
    "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
    "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL);",
    "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,timestamp INTEGER NOT NULL, data BLOB NOT NULL);",
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);",
]


def qos_yaml(transient_local):
    """offered_qos_profiles as Humble's rosbag2 records it (one publisher): reliable; transient_local for /tf_static."""
    return ("- history: 3\n  depth: 0\n  reliability: 1\n  durability: %d\n  deadline:\n    sec: 2147483647\n"
            "    nsec: 4294967295\n  lifespan:\n    sec: 2147483647\n    nsec: 4294967295\n  liveliness: 1\n"
            "  liveliness_lease_duration:\n    sec: 2147483647\n    nsec: 4294967295\n"
            "  avoid_ros_namespace_conventions: false" % (1 if transient_local else 2))


def metadata_yaml(file_name, topics, messages):
    """metadata.yaml text; topics [(name, type, qos)], messages [(topic_index, timestamp_ns)]."""
    start = min((t for _, t in messages), default=0)
    duration = max((t for _, t in messages), default=0) - start
    lines = ["rosbag2_bagfile_information:", "  version: 5", "  storage_identifier: sqlite3",
             "  duration:", f"    nanoseconds: {duration}", "  starting_time:", f"    nanoseconds_since_epoch: {start}",
             f"  message_count: {len(messages)}", "  topics_with_message_count:"]
    for i, (name, type_name, qos) in enumerate(topics):
        count = sum(1 for topic, _ in messages if topic == i)
        quoted = qos.replace("\n", "\\n").replace('"', '\\"')
        lines += ["    - topic_metadata:", f"        name: {name}", f"        type: {type_name}",
                  "        serialization_format: cdr", f'        offered_qos_profiles: "{quoted}"',
                  f"      message_count: {count}"]
    lines += ['  compression_format: ""', '  compression_mode: ""', "  relative_file_paths:", f"    - {file_name}",
              "  files:", f"    - path: {file_name}", "      starting_time:", f"        nanoseconds_since_epoch: {start}",
              "      duration:", f"        nanoseconds: {duration}", f"      message_count: {len(messages)}", ""]
    return "\n".join(lines)


def write_db3_bag(folder, topics, messages):
    """Write folder/metadata.yaml and folder/<folder name>_0.db3.

    topics: [(name, type like 'sensor_msgs/msg/PointCloud2', transient_local)];
    messages: iterable of (topic_index, timestamp_ns, cdr_bytes) in the order to insert (receive time).
    """
    os.makedirs(folder, exist_ok=True)
    file_name = os.path.basename(os.path.normpath(folder)) + "_0.db3"
    path = os.path.join(folder, file_name)
    if os.path.exists(path):
        os.remove(path)
    with_qos = [(name, type_name, qos_yaml(latched)) for name, type_name, latched in topics]
    db = sqlite3.connect(path)
    for sql in SCHEMA_SQL:
        db.execute(sql)
    db.execute("INSERT INTO schema VALUES (3, 'humble')")
    db.executemany("INSERT INTO topics(id, name, type, serialization_format, offered_qos_profiles) VALUES (?,?,?,?,?)",
                   [(i + 1, name, type_name, "cdr", qos) for i, (name, type_name, qos) in enumerate(with_qos)])
    times = []  # (topic index, timestamp) for metadata.yaml; messages may be a generator
    for t, ns, data in messages:
        db.execute("INSERT INTO messages(topic_id, timestamp, data) VALUES (?,?,?)", (t + 1, ns, sqlite3.Binary(data)))
        times.append((t, ns))
    meta = metadata_yaml(file_name, with_qos, times)
    db.execute("INSERT INTO metadata(metadata_version, metadata) VALUES (5, ?)", (meta,))
    db.commit()
    db.close()
    with open(os.path.join(folder, "metadata.yaml"), "w") as out:
        out.write(meta)
    return path


def read_db3_bag(folder):
    """{metadata (parsed YAML or None), topics {id: (name, type, format)}, messages [(topic_id, timestamp, data)]}.

    Messages come in (timestamp, id) order, as rosbag2's reader returns them.
    """
    meta = None
    meta_path = os.path.join(folder, "metadata.yaml")
    if os.path.exists(meta_path):
        import yaml
        with open(meta_path) as f:
            meta = yaml.safe_load(f)["rosbag2_bagfile_information"]
        files = meta["relative_file_paths"]
    else:
        files = sorted(f for f in os.listdir(folder) if f.endswith(".db3"))
    topics, messages = {}, []
    for name in files:
        db = sqlite3.connect(f"file:{os.path.join(folder, name)}?mode=ro", uri=True)
        for tid, topic, type_name, fmt in db.execute("SELECT id, name, type, serialization_format FROM topics"):
            topics[tid] = (topic, type_name, fmt)
        messages += db.execute("SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp, id").fetchall()
        db.close()
    return {"metadata": meta, "topics": topics, "messages": [(t, ns, bytes(d)) for t, ns, d in messages]}
