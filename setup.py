"""Build hook only (the metadata is in pyproject.toml): ship the user documentation in the wheel.

``tirecli report`` copies the model pages into the report folder so that its links work offline
and without the repository. The pages live in ``docs/`` (``docs/*.md``, ``docs/models/*.md``);
this copies them into the built package as ``tirecli/docs/`` (see :mod:`tirecli.report.docs`).
"""
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

HERE = Path(__file__).resolve().parent


class BuildPyWithDocs(build_py):
    """``build_py`` that also copies ``docs/*.md`` and ``docs/models/*.md`` to ``tirecli/docs/``."""

    def run(self):
        super().run()
        src = HERE / "docs"
        for page in sorted(src.glob("*.md")) + sorted(src.glob("models/*.md")):
            dest = Path(self.build_lib) / "tirecli" / "docs" / page.relative_to(src)
            self.mkpath(str(dest.parent))
            self.copy_file(str(page), str(dest))


setup(cmdclass={"build_py": BuildPyWithDocs})
