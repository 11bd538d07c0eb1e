"""The documentation as a reference (issue 49 item 1), checked without running anything (pure Python,
about a second):

- no tracked file names a folder of the machine it was made on (an absolute run folder such as
  /work/runs/..., a home or /tmp folder) or the machine's host name: a result or a page says where
  its files are relative to the project or to its case;
- every relative link and image of the pages (docs/**/*.md, README.md, cases/**/*.md) points to a
  file that exists, and every #anchor to a heading of the page it names;
- the data files (json, png) live in docs/data/, not among the pages.
"""
import os
import re
import socket
import subprocess

import pytest

from conftest import PROJECT

# A folder of one machine: the top-level folders where runs, clones and scratch files were kept. Not
# preceded by a word character, '.', '~', ':' or '/', so that URLs and relative paths (runs/..., a/tmp/b)
# do not count.
MACHINE_PATH = re.compile(r"(?<![\w.~:/-])/(?:work|root|home|Users|tmp|scratch|mnt|media|srv)/[\w.+-]")

# Tracked files that may name such a folder, and why.
ALLOWED = {
    # the C++ unit tests' scratch folders: /tmp/<prefix>.<pid>.<name>, made and removed by the tests
    "tests/support/scratch.h",
    # this test's own patterns
    "tests/test_docs.py",
}

BINARY_SUFFIXES = (".png", ".jpg", ".jpeg", ".gif", ".pdf", ".gz", ".tgz", ".zip", ".npy", ".npz", ".records")


def tracked_files():
    try:
        done = subprocess.run(["git", "-C", PROJECT, "ls-files", "-z"], capture_output=True, text=True)
    except OSError:
        pytest.skip("git is not installed")
    if done.returncode != 0:
        pytest.skip("not a git checkout: %s" % done.stderr.strip())
    return [p for p in done.stdout.split("\0") if p]


def tracked_text(path):
    """The text of a tracked file, or None for a binary one (or one deleted in the work tree)."""
    if path.endswith(BINARY_SUFFIXES):
        return None
    full = os.path.join(PROJECT, path)
    if not os.path.isfile(full):
        return None
    with open(full, "rb") as f:
        data = f.read()
    if b"\0" in data[:8192]:
        return None
    return data.decode("utf-8", errors="replace")


def test_no_machine_paths_in_tracked_files():
    found = []
    for path in tracked_files():
        if path in ALLOWED:
            continue
        text = tracked_text(path)
        if text is None:
            continue
        for number, line in enumerate(text.splitlines(), 1):
            m = MACHINE_PATH.search(line)
            if m:
                found.append("%s:%d: %s" % (path, number, line.strip()[:160]))
    assert not found, ("absolute folders of one machine in tracked files (write them relative to the project "
                       "or the case, or drop the field):\n" + "\n".join(found[:40]))


def test_no_host_name_in_tracked_files():
    host = socket.gethostname().split(".")[0]
    if len(host) < 5 or host.lower() in ("localhost", "ubuntu", "debian"):
        pytest.skip("host name %r too short or too common to look for" % host)
    word = re.compile(r"(?<![\w-])%s(?![\w-])" % re.escape(host), re.IGNORECASE)
    found = [path for path in tracked_files() if (lambda t: t is not None and word.search(t))(tracked_text(path))]
    assert not found, "this machine's host name %r in %s" % (host, ", ".join(found))


def test_the_machine_path_pattern():
    for bad in ("/work/runs/t8cal/x", "--workdir /tmp/overhead/run2", '"run_dir": "/root/x"', "(/home/u/a)"):
        assert MACHINE_PATH.search(bad), bad
    for good in ("runs/t8cal/x", "../runs/vreport", "https://example.org/home/page", "a/tmp/b",
                 "docs/data/x.json", "~/tmp/x", "/usr/lib/openfoam", "/proc/self/status"):
        assert not MACHINE_PATH.search(good), good


# ---- links ---------------------------------------------------------------------------------------

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
FENCE = re.compile(r"^(```|~~~).*?^\1", re.MULTILINE | re.DOTALL)
INLINE_CODE = re.compile(r"`[^`\n]*`")


def pages():
    out = [p for p in tracked_files() if p.endswith(".md") and
           (p.startswith("docs/") or p.startswith("cases/") or p in ("README.md", "CHANGES.md"))]
    assert "README.md" in out
    return out


def slug(heading):
    """GitHub's anchor of a heading: lower case, markup and punctuation dropped (letters, digits, spaces,
    '-' and '_' kept), spaces to '-'."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip())   # a link: its text
    text = text.replace("`", "").lower()
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors(path):
    text = FENCE.sub("", open(os.path.join(PROJECT, path), encoding="utf-8").read())
    seen, out = {}, set()
    for m in re.finditer(r"^#{1,6}\s+(.*?)\s*#*\s*$", text, re.MULTILINE):
        s = slug(m.group(1))
        n = seen.get(s, 0)
        seen[s] = n + 1
        out.add(s if n == 0 else "%s-%d" % (s, n))
    return out


def links(path):
    text = open(os.path.join(PROJECT, path), encoding="utf-8").read()
    text = INLINE_CODE.sub("", FENCE.sub("", text))
    for m in LINK.finditer(text):
        target = m.group(1)
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.IGNORECASE):   # http:, https:, mailto:
            continue
        yield target


def test_relative_links_resolve():
    broken = []
    for page in pages():
        for target in links(page):
            file_part, _, anchor = target.partition("#")
            resolved = os.path.normpath(os.path.join(os.path.dirname(page), file_part)) if file_part else page
            if not os.path.exists(os.path.join(PROJECT, resolved)):
                broken.append("%s: %s (no %s)" % (page, target, resolved))
            elif anchor and resolved.endswith(".md") and anchor not in anchors(resolved):
                broken.append("%s: %s (no heading #%s in %s)" % (page, target, anchor, resolved))
    assert not broken, "broken links:\n" + "\n".join(broken)


def test_link_parsing():
    assert slug("Checkpoint and resume") == "checkpoint-and-resume"
    assert slug("`fix fdm/couple` — the particle side") == "fix-fdmcouple--the-particle-side"
    assert slug("5.1 periodic array (Table 4)") == "51-periodic-array-table-4"
    text = "see [a](x.md#b), ![f](data/f.png) and [w](https://example.org) `[c](not/a/link)`"
    assert [m.group(1) for m in LINK.finditer(INLINE_CODE.sub("", text))] == ["x.md#b", "data/f.png",
                                                                               "https://example.org"]


def test_data_files_are_not_among_the_pages():
    docs = [p for p in tracked_files() if p.startswith("docs/")]
    astray = [p for p in docs if not p.startswith("docs/data/") and not p.endswith(".md")]
    assert not astray, "data files beside the pages (move them to docs/data/): %s" % ", ".join(astray)
