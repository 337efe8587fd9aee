"""Every relative link in README.md and docs/ leads somewhere: the file exists, and a
#section names a heading of that file (GitHub's anchors: lower case, punctuation dropped,
spaces as hyphens, a repeated heading numbered -1, -2, ...). Links inside code are not links.
"""
import glob
import os
import re
import tempfile
import unittest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^```.*?^```", re.S | re.M)
INLINE_CODE = re.compile(r"`[^`\n]*`")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$", re.M)


def documents():
    """README.md and every Markdown file under docs/, as paths relative to ROOT."""
    paths = ["README.md"] + sorted(glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))
    return [os.path.relpath(os.path.join(ROOT, p), ROOT) for p in paths]


def slug(heading):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link in a heading keeps its text
    text = text.lower().replace("`", "")
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(text):
    seen, out = {}, set()
    for heading in HEADING.findall(FENCE.sub("", text)):
        base = slug(heading)
        n = seen.get(base, 0)
        seen[base] = n + 1
        out.add(base if n == 0 else f"{base}-{n}")
    return out


def links(text):
    """The targets of the Markdown links of `text`, code blocks and inline code left out."""
    return LINK.findall(INLINE_CODE.sub("", FENCE.sub("", text)))


def broken(doc_path, text, root=ROOT):
    """A line per link of `text` (the file at doc_path, relative to root) that leads nowhere."""
    problems = []
    for target in links(text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        path, _, anchor = target.partition("#")
        file = os.path.normpath(os.path.join(root, os.path.dirname(doc_path), path)) if path else os.path.join(root, doc_path)
        if not os.path.exists(file):
            problems.append(f"{doc_path}: {target}: no such file")
            continue
        if anchor and file.endswith(".md"):
            with open(file, encoding="utf-8") as f:
                if anchor not in anchors(f.read()):
                    problems.append(f"{doc_path}: {target}: no heading with anchor #{anchor}")
    return problems


class DocsLinks(unittest.TestCase):
    def test_every_relative_link_of_the_readme_and_docs_leads_to_a_file_and_heading(self):
        problems = []
        for doc in documents():
            with open(os.path.join(ROOT, doc), encoding="utf-8") as f:
                problems += broken(doc, f.read())
        self.assertEqual(problems, [], "\n".join(problems))

    def test_the_readme_links_every_reference_file_in_docs(self):
        with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
            linked = {os.path.normpath(t.partition("#")[0]) for t in links(f.read())}
        for path in sorted(glob.glob(os.path.join(ROOT, "docs", "*.md"))):
            self.assertIn(os.path.relpath(path, ROOT), linked, "each docs/ topic is findable from the README")

    def test_a_missing_file_or_heading_is_found_and_code_and_web_links_are_not_links(self):
        with tempfile.TemporaryDirectory() as root:
            os.mkdir(os.path.join(root, "docs"))
            with open(os.path.join(root, "docs", "topic.md"), "w", encoding="utf-8") as f:
                f.write("# Topic\n\n## Ray files (`.npy`)\n")
            text = ("[ok](docs/topic.md#ray-files-npy) [self](#readme) [gone](docs/none.md) "
                    "[bad](docs/topic.md#rays) [bad here](#nowhere) `[in code](x.md)` "
                    "[web](https://example.org/x.md)\n\n```\n[fenced](y.md)\n```\n\n# README\n")
            with open(os.path.join(root, "README.md"), "w", encoding="utf-8") as f:
                f.write(text)
            self.assertEqual(broken("README.md", text, root), [
                "README.md: docs/none.md: no such file",
                "README.md: docs/topic.md#rays: no heading with anchor #rays",
                "README.md: #nowhere: no heading with anchor #nowhere",
            ])

    def test_anchors_follow_github(self):
        self.assertEqual(slug("Ray files (`.npy`)"), "ray-files-npy")
        self.assertEqual(slug("Moving a scene, and sweeps"), "moving-a-scene-and-sweeps")
        self.assertEqual(slug("The wide BVH (`bvh8`)"), "the-wide-bvh-bvh8")
        self.assertEqual(anchors("# A\n\n## A\n"), {"a", "a-1"})


if __name__ == "__main__":
    unittest.main()
