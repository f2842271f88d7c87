"""MkDocs hook: the TeX of ``$...$`` and ``$$...$$`` (marked by pymdownx.arithmatex, generic mode) becomes
MathML when the site is built, so equations render in any current browser with no script and no network.

Pages and docstrings (mkdocstrings renders them with the same Markdown extensions) both pass through here.
"""

from __future__ import annotations

import html
import re

from latex2mathml.converter import convert

_INLINE = re.compile(r'<span class="arithmatex">\\\((.*?)\\\)</span>', re.S)
_DISPLAY = re.compile(r'<div class="arithmatex">\\\[(.*?)\\\]</div>', re.S)


def _mathml(tex: str, display: str) -> str:
    return convert(html.unescape(tex).strip(), display=display)


def on_page_content(content: str, **kwargs) -> str:
    content = _DISPLAY.sub(lambda m: _mathml(m[1], "block"), content)
    return _INLINE.sub(lambda m: _mathml(m[1], "inline"), content)
