"""The code cites the project's own documents (issue #31: docs in the repository): no docstring or comment in
``volviz`` or ``app`` refers to the design notes kept outside the repository, and every citation of a section,
``docs/NAME.md "Section"``, names a file of ``docs/`` and a heading in it."""
from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CITATION = re.compile(r'docs/([\w/.-]+\.md) "([^"]+)"')


def sources() -> list[Path]:
    return sorted([*(ROOT / "volviz").rglob("*.py"), *(ROOT / "app").rglob("*.py")])


def headings(doc: Path) -> set[str]:
    return {line.lstrip("#").strip() for line in doc.read_text(encoding="utf-8").splitlines() if line.startswith("#")}


def test_no_source_cites_the_design_notes_outside_the_repository() -> None:
    citing = [str(path.relative_to(ROOT)) for path in sources() if "DESIGN.md" in path.read_text(encoding="utf-8")]
    assert citing == []


def test_every_cited_section_is_a_heading_of_a_document_in_docs() -> None:
    cited = 0
    wrong = []
    for path in sources():
        text = re.sub(r"\s*\n\s*(#\s*)?", " ", path.read_text(encoding="utf-8"))  # citations wrap across lines
        for name, section in CITATION.findall(text):
            cited += 1
            doc = ROOT / "docs" / name
            if not doc.is_file() or section not in headings(doc):
                wrong.append(f"{path.relative_to(ROOT)}: docs/{name} \"{section}\"")
    assert wrong == []
    assert cited >= 10  # the citations moved from the outside notes to docs/design.md
