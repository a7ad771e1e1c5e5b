"""The built-in classical controllers and references, one module per family.

Importing this package imports none of them: the registry lists them by entry point
(:data:`shipgym_baselines.controllers.BUILTINS`) and imports a module when its controller
is made.
"""
