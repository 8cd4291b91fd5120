#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""tests/docs/check.py SOURCE_DIR [UMBRA_BENCH]: the docs check run by ctest (docs_check).

- every relative link and image in README.md, docs/*.md, bench/README.md and bench/results/**/*.md
  resolves to a file in the tree, and a `#fragment` to a heading of its target (GitHub's anchors);
- README.md stays a guide: at most MAX_README_LINES lines;
- no text there names the project's own work history other than by commit or date (a numbered
  round of work, "this session", and the like: the patterns below);
- with UMBRA_BENCH, `umbra-bench readme --check` passes: the generated blocks are current.
Prints each problem as FILE:LINE: message and exits 1 if there is any."""
import pathlib
import re
import subprocess
import sys
import unicodedata

MAX_README_LINES = 350
LINK = re.compile(r'!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(([^()\s]+)(?:\s+"[^"]*")?\)')
HISTORY = re.compile(
    r'\b(?:stops?|sessions?) \d+\b'
    r'|\b(?:this|that|the previous|the next|an earlier|earlier|a later|the same|same|each)'
    r'[ -](?:stop|session)s?\b(?! (?:the|it|at|when|once))'
    r'|\b(?:for|in|of) (?:the|a|that|this) session\b|\bother helpers\b|\bissue workers?\b',
    re.IGNORECASE)


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to '-'."""
    text = re.sub(r'`([^`]*)`', r'\1', heading.strip())
    text = re.sub(r'\[([^\]]*)\]\([^)]*\)', r'\1', text)
    text = text.lower()
    out = []
    for ch in text:
        cat = unicodedata.category(ch)
        if ch in ' -':
            out.append('-' if ch == ' ' else ch)
        elif ch == '_' or cat[0] in 'LN' or cat == 'Mn':
            out.append(ch)
    return ''.join(out)


def lines(path):
    """(line number, text) of the lines outside code fences."""
    fence = False
    for n, line in enumerate(path.read_text(encoding='utf-8').split('\n'), 1):
        if line.lstrip().startswith('```'):
            fence = not fence
        elif not fence:
            yield n, line


def anchors(path, cache={}):
    if path not in cache:
        seen, found = {}, set()
        for _, line in lines(path):
            m = re.match(r'#{1,6}\s+(.*?)\s*#*\s*$', line)
            if m:
                s = slug(m.group(1))
                k = seen.get(s, 0)
                seen[s] = k + 1
                found.add(s if k == 0 else f'{s}-{k}')
        # explicit <a id="..."> / <a name="...">
        found |= set(re.findall(r'<a\s+(?:id|name)="([^"]+)"', path.read_text(encoding='utf-8')))
        cache[path] = found
    return cache[path]


def main():
    if len(sys.argv) not in (2, 3):
        print(__doc__)
        return 2
    root = pathlib.Path(sys.argv[1]).resolve()
    files = [root / 'README.md', root / 'bench' / 'README.md']
    files += sorted((root / 'docs').glob('*.md'))
    files += sorted((root / 'bench' / 'results').rglob('*.md'))
    problems = []
    for f in files:
        rel = f.relative_to(root)
        for n, line in lines(f):
            prose = re.sub(r'`[^`]*`', '', line)
            for m in HISTORY.finditer(prose):
                problems.append(f'{rel}:{n}: names the work history ("{m.group(0)}"): '
                                'use a commit or date')
            for m in LINK.finditer(line):
                target = m.group(1)
                if re.match(r'^[a-z][a-z0-9+.-]*:', target):  # http:, https:, mailto:
                    continue
                path, _, frag = target.partition('#')
                dest = (f.parent / path).resolve() if path else f
                if not dest.exists():
                    problems.append(f'{rel}:{n}: link to {target}: no such file')
                    continue
                if frag and dest.suffix == '.md' and frag not in anchors(dest):
                    problems.append(f'{rel}:{n}: link to {target}: {dest.name} has no '
                                    f'heading #{frag}')
    count = len((root / 'README.md').read_text(encoding='utf-8').split('\n')) - 1
    if count > MAX_README_LINES:
        problems.append(f'README.md: {count} lines, more than {MAX_README_LINES}: '
                        'move detail to docs/')
    for p in problems:
        print(p)
    rc = 1 if problems else 0
    if len(sys.argv) == 3:
        r = subprocess.run([sys.argv[2], 'readme', '--check'])
        if r.returncode != 0:
            print('umbra-bench readme --check failed: run build/umbra-bench readme')
            rc = 1
    print(f'docs check: {len(files)} files, README.md {count} lines, {len(problems)} problems')
    return rc


if __name__ == '__main__':
    sys.exit(main())
