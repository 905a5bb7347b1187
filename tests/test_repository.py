"""The tracked files: they speak of the project's topics, never of tracker entries, and the
results under docs/ stay light (bulky data is written again by the command its README gives)."""

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

DOCS_FILE_LIMIT = 2_000_000  # bytes
DOCS_TOTAL_LIMIT = 25_000_000  # bytes, all tracked files under docs/ together

# A tracker word (issue, ticket, PR, pull request; any case, plural too) followed by a number, with
# or without "#". The examples below are assembled from parts, so that this file holds none.
TRACKER_REFERENCE = re.compile(r"\b(issues?|tickets?|PR|pull requests?)(\s+#?|\s*#)\d+\b", re.IGNORECASE)


def tracked_files() -> list[str]:
    """Paths (from the repository root) of the files git tracks that exist in the work tree."""
    try:
        listed = subprocess.run(
            ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True, timeout=60
        ).stdout
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git work tree")
    return [p for p in listed.decode().split("\0") if p and (ROOT / p).is_file()]


def tracker_references(text: str) -> list[str]:
    """The tracker references in `text`, as written."""
    return [match.group(0) for match in TRACKER_REFERENCE.finditer(text)]


EXAMPLES = [("issue", " ", 19), ("Issue", " ", 22), ("issues", " #", 3), ("ticket", " ", 7), ("PR", " #", 12)]


def test_the_pattern_finds_tracker_references():
    references = [f"{word}{gap}{number}" for word, gap, number in EXAMPLES]
    text = f"see {references[0]} and {', '.join(references[1:])}; label #0, the issues, base64 +PR0a"
    assert tracker_references(text) == references


def test_no_tracked_file_refers_to_the_tracker():
    found = {}
    for path in tracked_files():
        data = (ROOT / path).read_bytes()
        if b"\0" in data[:8192]:  # binary files
            continue
        references = tracker_references(data.decode("utf-8", errors="replace"))
        if references:
            found[path] = references
    assert found == {}


def test_no_tracked_file_under_docs_is_over_the_limit():
    sizes = {path: (ROOT / path).stat().st_size for path in tracked_files() if path.startswith("docs/")}
    assert sizes, "no tracked file under docs/"
    assert {path: size for path, size in sizes.items() if size > DOCS_FILE_LIMIT} == {}


def test_the_tracked_files_under_docs_stay_under_the_total():
    """Figures are palette PNGs and bulky JSON is written without indentation, which keeps docs/ light."""
    sizes = [(ROOT / path).stat().st_size for path in tracked_files() if path.startswith("docs/")]
    assert sizes, "no tracked file under docs/"
    assert sum(sizes) <= DOCS_TOTAL_LIMIT, f"docs/ holds {sum(sizes)} bytes, over {DOCS_TOTAL_LIMIT}"
