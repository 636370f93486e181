"""The reference pages hold to what they promise a reader: each page of docs/ under 300 lines, every relative
link and picture there, every repository file a page names (`scripts/bench.sh`, `tests/unit/...`) present,
and no path of a developer's machine in them."""
import pathlib
import re

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAGES = sorted((ROOT / "docs").rglob("*.md")) + [ROOT / "README.md", ROOT / "scripts" / "farm" / "README.md"]
LINK = re.compile(r"\]\(([^)\s]+)\)")
# A repository file or folder named in a page: a top-level folder of the project, then a path.
NAMED = re.compile(r"(?<![\w/.-])((?:core|plugins|ptex_support|scripts|tests|docs)/[A-Za-z0-9_/-]+(?:\.[A-Za-z0-9]+)?)")
MACHINE = re.compile(r"(?<![\w.])(?:/(?:home|work|root|tmp|mnt|Users)/\w|[A-Z]:\\\\\w)")


def relative(page):
    return page.relative_to(ROOT).as_posix()


@pytest.mark.parametrize("page", [p for p in PAGES if ROOT / "docs" in p.parents], ids=relative)
def test_page_under_300_lines(page):
    lines = page.read_text(encoding="utf-8").count("\n")
    assert lines < 300, f"{relative(page)} has {lines} lines (expected under 300)"


@pytest.mark.parametrize("page", PAGES, ids=relative)
def test_links_and_named_files_exist(page):
    text = page.read_text(encoding="utf-8")
    missing = []
    for target in LINK.findall(text):
        if re.match(r"[a-z]+:", target) or target.startswith("#"):
            continue  # a URL or an anchor on the same page
        path = target.split("#", 1)[0]
        if not (page.parent / path).exists():
            missing.append(f"link {target}")
    for name in NAMED.findall(text):
        if not (ROOT / name).exists():
            missing.append(f"file {name}")
    assert not missing, f"{relative(page)}: " + "; ".join(missing)


@pytest.mark.parametrize("page", PAGES + [ROOT / "CHANGELOG.md"], ids=relative)
def test_no_machine_paths(page):
    found = [m.group(0) for m in MACHINE.finditer(page.read_text(encoding="utf-8"))]
    assert not found, f"{relative(page)} names a machine's path: {found}"
