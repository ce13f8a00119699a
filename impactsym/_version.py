"""The package version: the one place it is written (pyproject.toml reads it
through hatch's ``[tool.hatch.version]``; ``impactsym --version`` prints it)."""

__version__ = "0.1.0"
