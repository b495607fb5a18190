"""The library's one loose type, with the reason it is loose (the type checker: ``[tool.mypy]`` in pyproject.toml)."""

from typing import Any, TypeAlias

#: A value of a YAML or JSON document (a design, the workflow's config, a study's spec, a claim's spec) or of a
#: netCDF attribute: a str, number, bool, array, list or mapping of these.  The JSON schemas
#: (``geardyn/config/schemas``) check a document where it enters; the code then reads it by key, so its values are
#: not typed one by one.
Json: TypeAlias = Any
