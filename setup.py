"""Only for Binder: everything about the package is in pyproject.toml.

Binder builds its image with repo2docker, which installs a repository that has a setup.py with
`pip install .`. Some releases of repo2docker fail on a repository that has a pyproject.toml and
no setup.py, so this file keeps the Binder build working with any release.
"""

from setuptools import setup

setup()
