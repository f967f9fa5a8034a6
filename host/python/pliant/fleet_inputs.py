"""What a fleet batch takes in: the recordings, their content keys and their object classes.

A batch names recordings by directory (every directory below it that holds a recording.json)
or by list file (one recording directory per line). Each (recording, job) pair is identified by
a key: SHA-256 over the job, its options and the bytes of recording.json and of every file
recording.json references, so a recording that is copied or moved keeps its key and one whose
data changed gets a new one. Pure Python; nothing here runs the command line.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field

RECORDING_JSON = "recording.json"
KEY_VERSION = b"pliant-fleet-key/1"
_CHUNK_BYTES = 1 << 20


class UsageError(Exception):
    """A mistake in how the batch was asked for (its command line exits 2 with the message)."""


@dataclass
class Recording:
    """One recording directory of a batch.

    path: as the user named it (relative names stay relative, for the table);
    abspath: absolute, for the workers, whose working directory is elsewhere;
    object: the object class read from recording.json (the --class-key path, "" if absent);
    digests: (file name relative to the directory, SHA-256 hex or a marker) sorted by name.
    """

    path: str
    abspath: str
    object: str = ""
    digests: list = field(default_factory=list)


def find_recordings(sources):
    """The recordings named by `sources` (directories and list files), in a stable order.

    A directory is searched recursively; a directory holding recording.json is a recording and
    is not searched further. A list file names one recording directory per line (relative to
    the list file's directory; blank lines and lines starting with '#' are skipped). The same
    directory named twice is taken once. Raises UsageError for a source that does not exist, a
    list entry that is not a recording directory, or no recording at all.
    """
    found = []
    seen = set()
    for source in sources:
        if os.path.isdir(source):
            candidates = _walk(source)
        elif os.path.isfile(source):
            candidates = _read_list_file(source)
        else:
            raise UsageError(f"{source}: no such directory or list file")
        for path in candidates:
            real = os.path.realpath(path)
            if real not in seen:
                seen.add(real)
                found.append(path)
    if not found:
        raise UsageError("no recordings (directories holding a recording.json) in " + ", ".join(sources))
    return found


def _walk(root):
    recordings = []
    for directory, subdirectories, files in os.walk(root):
        if RECORDING_JSON in files:
            recordings.append(os.path.normpath(directory))
            subdirectories[:] = []  # a recording holds no recordings
        else:
            subdirectories.sort()
    recordings.sort()
    return recordings


def _read_list_file(list_path):
    base = os.path.dirname(list_path)
    recordings = []
    with open(list_path, encoding="utf-8") as lines:
        for number, line in enumerate(lines, start=1):
            entry = line.strip()
            if not entry or entry.startswith("#"):
                continue
            path = os.path.normpath(entry if os.path.isabs(entry) else os.path.join(base, entry))
            if not os.path.isfile(os.path.join(path, RECORDING_JSON)):
                raise UsageError(f"{list_path}:{number}: {entry} is not a recording directory (no {RECORDING_JSON})")
            recordings.append(path)
    return recordings


def describe_recording(path, class_key="meta.object"):
    """Reads one recording's object class and the digests of its files (see Recording).

    Never raises on a malformed recording: a recording.json that does not parse is hashed as
    bytes and has no class; a referenced file that is missing or unreadable is hashed as a
    marker, so it still gets a key (and its row the command line's error).
    """
    recording = Recording(path=path, abspath=os.path.abspath(path))
    json_path = os.path.join(recording.abspath, RECORDING_JSON)
    document = None
    try:
        with open(json_path, "rb") as stream:
            document = json.loads(stream.read().decode("utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        document = None
    if isinstance(document, dict):
        recording.object = object_class(document, class_key)
    names = {RECORDING_JSON} | set(referenced_files(document))
    recording.digests = [(name, _file_digest(recording.abspath, name)) for name in sorted(names)]
    return recording


def object_class(document, class_key):
    """The value at the dotted path `class_key` ("meta.object") of recording.json, as text."""
    value = document
    for part in class_key.split("."):
        if not isinstance(value, dict) or part not in value:
            return ""
        value = value[part]
    if value is None:
        return ""
    return value if isinstance(value, str) else json.dumps(value, sort_keys=True)


def referenced_files(document):
    """The relative file names recording.json's "files" names (particles, wrench, mesh, media)."""
    if not isinstance(document, dict) or not isinstance(document.get("files"), dict):
        return []
    return [name for name in document["files"].values() if isinstance(name, str) and name]


def _file_digest(directory, name):
    target = os.path.realpath(os.path.join(directory, name))
    root = os.path.realpath(directory)
    if os.path.commonpath([root, target]) != root:
        return "outside-the-recording"  # the reader refuses it; its content is not ours to read
    digest = hashlib.sha256()
    try:
        with open(target, "rb") as stream:
            while True:
                chunk = stream.read(_CHUNK_BYTES)
                if not chunk:
                    break
                digest.update(chunk)
    except FileNotFoundError:
        return "missing"
    except IsADirectoryError:
        return "directory"
    except OSError as error:
        return "unreadable: " + (error.strerror or type(error).__name__)
    return digest.hexdigest()


def task_key(recording, job, options):
    """SHA-256 hex of the job, its options (with the digests of option files) and the recording's files."""
    digest = hashlib.sha256()

    def put(text):
        data = text.encode("utf-8")
        digest.update(len(data).to_bytes(8, "big"))
        digest.update(data)

    put(KEY_VERSION.decode())
    put(job)
    put(json.dumps(list(options)))
    for argument in options:
        path = option_value(argument)
        if path and os.path.isabs(path) and os.path.isfile(path):
            put("option file " + path)
            put(_file_digest(os.path.dirname(path), os.path.basename(path)))
    for name, file_digest in recording.digests:
        put(name)
        put(file_digest)
    return digest.hexdigest()


def option_value(argument):
    """The value part of "--flag=value", or the argument itself."""
    if argument.startswith("-") and "=" in argument:
        return argument.split("=", 1)[1]
    return argument


def absolute_option_files(options):
    """`options` with every value that names an existing file made absolute (workers run elsewhere)."""
    result = []
    for argument in options:
        value = option_value(argument)
        if value and not os.path.isabs(value) and os.path.isfile(value):
            absolute = os.path.abspath(value)
            argument = argument[: len(argument) - len(value)] + absolute if argument != value else absolute
        result.append(argument)
    return result
