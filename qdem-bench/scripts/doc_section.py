"""Rewrites the part of a Markdown file between two markers, for the study scripts that keep
their tables in docs/."""

import os


def replace_section(path, begin, end, lines):
    """Replaces what lies between the markers `begin` and `end` of the file at `path` with
    `lines`, one per line, through a temporary file so that a failed write leaves the old
    file whole."""
    text = open(path).read()
    i, j = text.index(begin) + len(begin), text.index(end)
    text = text[:i] + "\n" + "\n".join(lines) + "\n" + text[j:]
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)
