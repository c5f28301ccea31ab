"""USD's own validators on a written ``.usda`` / ``.usdz``, the ``usdchecker`` way.

:func:`validate_usd` runs every validator of ``pxr.UsdValidation``'s
``ValidationRegistry`` (those behind ``usdchecker``: core, UsdGeom, UsdShade,
including ``NormalMapTextureValidator`` and ``ShaderSdrCompliance``, and the
usdz package rules) and returns their findings.

One finding is answered by a second check instead: the usd-core wheel ships
no usdMtlx plugin, so its shader registry (Sdr) knows no MaterialX node and
``ShaderSdrCompliance`` reports every ``ND_*`` id of the ``mtlx`` render
context as ``MissingShaderIdInRegistry``. Renderers built with MaterialX
(Storm, Karma, Omniverse) register those ids from MaterialX's own library, so
:func:`materialx_id_problems` checks each such shader against that library:
the nodedef exists, and every authored input is one of its inputs, with the
USD type usdMtlx gives the nodedef's type. Only findings that check answers
are dropped.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from pxr import Usd, UsdShade, UsdValidation

from .mtlx import standard_library
from .usd_mtlx import SDF_TYPES

_MISSING_ID = "MissingShaderIdInRegistry"


@dataclass(frozen=True)
class Finding:
    """One validator finding: ``Error``, ``Warn`` or ``Info``, its name and message."""

    severity: str
    name: str
    message: str

    def __str__(self) -> str:
        return f"{self.severity} {self.name}: {self.message}"


def materialx_id_problems(shader: UsdShade.Shader) -> list[str]:
    """Why ``shader`` (an ``ND_*`` id) does not match MaterialX's library; [] if it does."""
    shader_id = shader.GetIdAttr().Get()
    nodedef = standard_library().getNodeDef(shader_id)
    where = shader.GetPath()
    if nodedef is None:
        return [f"{where}: {shader_id} is not a MaterialX nodedef"]
    problems = []
    for usd_input in shader.GetInputs():
        name = usd_input.GetBaseName()
        port = nodedef.getActiveInput(name)
        if port is None:
            problems.append(f"{where}: {shader_id} has no input {name!r}")
        elif SDF_TYPES.get(port.getType()) != usd_input.GetTypeName():
            problems.append(
                f"{where}: input {name!r} is {usd_input.GetTypeName()}, "
                f"{shader_id} wants {port.getType()}"
            )
    for usd_output in shader.GetOutputs():
        port = nodedef.getActiveOutput(usd_output.GetBaseName())
        if port is None or SDF_TYPES.get(port.getType()) != usd_output.GetTypeName():
            problems.append(f"{where}: output {usd_output.GetBaseName()!r} does not match")
    return problems


def _shader_at(error: UsdValidation.ValidationError) -> UsdShade.Shader | None:
    """The shader an error is about (its site is the prim or its ``info:id``)."""
    for site in error.GetSites():
        prim = site.GetPrim() if site.IsPrim() else site.GetProperty().GetPrim()
        if prim and UsdShade.Shader(prim):
            return UsdShade.Shader(prim)
    return None


def validate_usd(path: str | os.PathLike) -> list[Finding]:
    """Every validator's findings on the stage at ``path`` (errors, warnings and infos),
    with MaterialX ids checked against MaterialX's library (module docstring)."""
    stage = Usd.Stage.Open(os.fspath(path))
    if stage is None:
        return [Finding("Error", "Open", f"USD cannot open {path}")]
    validators = UsdValidation.ValidationRegistry().GetOrLoadAllValidators()
    context = UsdValidation.ValidationContext(validators)
    findings = []
    for error in context.Validate(stage):
        severity = error.GetType().displayName
        shader = _shader_at(error) if error.GetName() == _MISSING_ID else None
        if shader is not None and shader.GetIdAttr().Get().startswith("ND_"):
            problems = materialx_id_problems(shader)
            findings += [Finding("Error", "MaterialXNodeDef", p) for p in problems]
        else:
            findings.append(Finding(severity, error.GetName(), error.GetMessage()))
    return findings
