"""What a model file's text may hold, checked before MuJoCo parses it: no DTD or entity declarations, includes
inside the model's folder, finite numbers (MuJoCo's parser would put its default in place of NaN)."""

from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from trms.errors import ModelFileError

__all__ = ["refuse_declarations_and_outside_includes", "refuse_non_finite_numbers"]

_INCLUDE = re.compile(rb"<include\s[^>]*file\s*=\s*[\"']([^\"']+)[\"']")


def refuse_declarations_and_outside_includes(path: Path, folder: Path, allow_outside: bool, seen: set[Path]) -> None:
    """Refuse a DTD or entity declaration (MJCF has no use for one; an entity can expand without bound) and an
    ``<include>`` outside ``folder`` (unless ``allow_outside``), in ``path`` and every file it includes.

    Examples
    --------
    >>> import tempfile
    >>> p = Path(tempfile.mkdtemp()) / "m.xml"
    >>> _ = p.write_text('<mujoco><include file="/etc/passwd"/></mujoco>')
    >>> refuse_declarations_and_outside_includes(p, p.parent, False, set())
    Traceback (most recent call last):
    ...
    trms.errors.ModelFileError: model file '...m.xml' includes '/etc/passwd', outside the model's folder ...
    """
    path = path.resolve()
    if path in seen:
        return
    seen.add(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ModelFileError(f"model file {str(path)!r} cannot be read: {exc.strerror}") from exc
    text = re.sub(rb"<!--.*?-->", b"", raw, flags=re.S)
    if re.search(rb"<!(DOCTYPE|ENTITY)", text, flags=re.I):
        raise ModelFileError(
            f"model file {str(path)!r} declares a DTD or entities; allowed: plain MJCF without <!DOCTYPE> or <!ENTITY>"
        )
    for name in _INCLUDE.findall(text):
        included = (path.parent / os.fsdecode(name)).resolve()
        if not allow_outside and not included.is_relative_to(folder):
            raise ModelFileError(
                f"model file {str(path)!r} includes {os.fsdecode(name)!r}, outside the model's folder "
                f"{str(folder)!r}; allowed: files inside it (or load_spec(..., allow_outside_includes=True))"
            )
        if included.is_file():
            refuse_declarations_and_outside_includes(included, folder, allow_outside, seen)


def refuse_non_finite_numbers(path: Path) -> None:
    """Refuse NaN/inf in any numeric attribute: MuJoCo's parser would replace it by its default.

    Examples
    --------
    >>> import tempfile
    >>> p = Path(tempfile.mkdtemp()) / "m.xml"
    >>> _ = p.write_text('<mujoco><option timestep="nan"/></mujoco>')
    >>> refuse_non_finite_numbers(p)
    Traceback (most recent call last):
    ...
    trms.errors.ModelFileError: model file '...m.xml': <option> timestep="nan" is not finite; allowed: finite ...
    """
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError:
        return  # not well-formed: MuJoCo's parser reports it with its own message
    for element in root.iter():
        for attr, value in element.attrib.items():
            tokens = value.split()
            try:
                numbers = [float(t) for t in tokens]
            except ValueError:
                continue  # a name or a file, not numbers
            if tokens and not np.all(np.isfinite(numbers)):
                name = element.get("name")
                where = f"<{element.tag}{f' name={name!r}' if name else ''}>"
                raise ModelFileError(
                    f'model file {str(path)!r}: {where} {attr}="{value}" is not finite; allowed: '
                    "finite numbers (MuJoCo would silently put its default in place of NaN)"
                )
