#!/usr/bin/env python3
"""clang-tidy over the translation units of a compile database whose paths start with one of the
given folders, in parallel, with a result cache.

A unit's cache key is the hash of the .clang-tidy configuration, the clang-tidy version, the
unit's compile command and its preprocessed text (so an edited header invalidates every unit that
includes it). A clean unit leaves an empty file named by its key; a unit with findings is never
cached. Prints the findings; exits 1 when any unit has one.

Usage: lint_tidy.py CLANG_TIDY BUILD_DIR CACHE_DIR JOBS FOLDER [FOLDER ...]
"""
import concurrent.futures
import hashlib
import json
import os
import shlex
import subprocess
import sys


def preprocess_command(entry):
    """The unit's compile command with -E instead of compiling to an object file."""
    args = entry["arguments"] if "arguments" in entry else shlex.split(entry["command"])
    out = []
    skip = False
    for arg in args:
        if skip:
            skip = False
            continue
        if arg == "-o":
            skip = True
            continue
        if arg in ("-c", "-MD", "-MMD") or arg.startswith(("-MF", "-MT", "-MQ")):
            if arg in ("-MF", "-MT", "-MQ"):
                skip = True
            continue
        out.append(arg)
    if out and os.path.basename(out[0]) == "ccache":
        out = out[1:]
    return out + ["-E", "-P", "-o", "-"]


def cache_key(entry, salt):
    """The key of a unit; the checkout's own path is taken out, so that clones elsewhere share it."""
    root = os.getcwd()
    text = subprocess.run(preprocess_command(entry), cwd=entry["directory"], capture_output=True, check=False).stdout
    digest = hashlib.sha256(salt)
    command = entry.get("command", " ".join(entry.get("arguments", [])))
    digest.update(command.replace(root, "<root>").encode())
    digest.update(text.replace(root.encode(), b"<root>"))
    return digest.hexdigest()[:40]


def check(entry, clang_tidy, build, cache, salt):
    key = cache_key(entry, salt)
    stamp = os.path.join(cache, key)
    if os.path.exists(stamp):
        return entry["file"], True, ""
    result = subprocess.run([clang_tidy, "--quiet", "-p", build, entry["file"]], capture_output=True, text=True,
                            check=False)
    findings = [line for line in (result.stdout + result.stderr).splitlines()
                if ("warning:" in line or "error:" in line) and "warnings generated" not in line]
    if result.returncode == 0 and not findings:
        open(stamp, "w").close()
        return entry["file"], True, ""
    return entry["file"], False, "\n".join(findings) or result.stdout + result.stderr


def main():
    clang_tidy, build, cache, jobs = sys.argv[1:5]
    folders = tuple(os.path.abspath(folder) + os.sep for folder in sys.argv[5:])
    os.makedirs(cache, exist_ok=True)
    with open(os.path.join(build, "compile_commands.json")) as handle:
        entries = [e for e in json.load(handle)
                   if os.path.abspath(os.path.join(e["directory"], e["file"])).startswith(folders)]
    version = subprocess.run([clang_tidy, "--version"], capture_output=True, check=False).stdout
    with open(".clang-tidy", "rb") as handle:
        salt = handle.read() + version
    failed = 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=int(jobs)) as pool:
        for unit, clean, report in pool.map(lambda e: check(e, clang_tidy, build, cache, salt), entries):
            if not clean:
                failed += 1
                print(f"lint tidy: {os.path.relpath(unit)}:\n{report}")
    print(f"lint tidy: {len(entries) - failed} of {len(entries)} units clean")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
