"""The built-in classical controllers and references.

Importing this package imports the modules that register them
(:func:`shipgym_baselines.registry.register_controller`), in the order the registry lists
them; :func:`shipgym_baselines.registry._load_builtins` imports it before any read of the
registry.
"""

# the import order is the registration order (CONTROLLERS and the docs' index list it)
# isort: off
from shipgym_baselines.classical import pid, lqr, l1_backstepping, nmpc, reference, oracle, nmpc_ekf
# isort: on

__all__ = ["l1_backstepping", "lqr", "nmpc", "nmpc_ekf", "oracle", "pid", "reference"]
