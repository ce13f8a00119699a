"""Characters the plotting font cannot draw (a vehicle named with emoji or
CJK): matplotlib warns once per glyph and drawing pass, with its source path;
impactsym says it once, in one line, naming the characters."""

from __future__ import annotations

import contextlib
import re
import warnings
from collections.abc import Iterator

__all__ = ["MissingGlyphWarning", "one_glyph_warning"]

_MISSING = re.compile(r"Glyph \d+ \((.*?)\) missing from font\(s\) (.*)\.$")


class MissingGlyphWarning(UserWarning):
    """Some characters of the labels are not in the plotting font."""


@contextlib.contextmanager
def one_glyph_warning() -> Iterator[None]:
    """Collect matplotlib's missing-glyph warnings while drawing and issue one
    :class:`MissingGlyphWarning` naming the characters (other warnings pass)."""
    missing: dict[str, str] = {}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    for item in caught:
        match = _MISSING.match(str(item.message))
        if match:
            name = match.group(1).removeprefix("\\N{").removesuffix("}")
            missing.setdefault(_char(name), match.group(2))
        else:
            warnings.warn_explicit(item.message, item.category, item.filename, item.lineno)
    if missing:
        fonts = ", ".join(sorted(set(missing.values())))
        warnings.warn(
            f"the plotting font ({fonts}) has no glyph for {' '.join(missing)} in the labels: they are "
            "drawn as boxes (install a font that has them, e.g. Noto Sans CJK, and set "
            "matplotlib's font.family; or use other names)",
            MissingGlyphWarning,
            stacklevel=3,
        )


def _char(name: str) -> str:
    import unicodedata

    try:
        return unicodedata.lookup(name)
    except KeyError:
        return name
