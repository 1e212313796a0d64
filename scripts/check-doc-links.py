#!/usr/bin/env python3
"""Checks the relative links of the tracked Markdown files: each target file exists and each #anchor names a
heading of its file (GitHub's rule: lower case, punctuation dropped, spaces as hyphens). Prints every broken link
and exits 1 if there is one. Links to web addresses are not followed.
usage: scripts/check-doc-links.py [FILE.md ...]   (default: every tracked *.md)"""
import os
import re
import subprocess
import sys

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
os.chdir(root)


def anchors(path):
    seen, out = {}, set()
    in_code = False
    for line in open(path, encoding="utf-8"):
        if line.lstrip().startswith("```"):
            in_code = not in_code
        m = None if in_code else re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        slug = re.sub(r"[^\w\- ]", "", m.group(1).strip().lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


files = sys.argv[1:] or subprocess.run(["git", "ls-files", "*.md"], capture_output=True, text=True).stdout.split()
broken = 0
for md in files:
    text = open(md, encoding="utf-8").read()
    text = re.sub(r"```.*?```", "", text, flags=re.S)  # links inside code blocks are not links
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # http:, https:, mailto:
            continue
        path, _, anchor = target.partition("#")
        resolved = os.path.normpath(os.path.join(os.path.dirname(md), path)) if path else md
        if not os.path.exists(resolved):
            print(f"{md}: {target}: no such file {resolved}")
            broken += 1
        elif anchor and resolved.endswith(".md") and anchor not in anchors(resolved):
            print(f"{md}: {target}: no heading #{anchor} in {resolved}")
            broken += 1
print(f"check-doc-links: {len(files)} files, {broken} broken links")
sys.exit(1 if broken else 0)
