"""What the tests share: models, designs, checks and paths, each in a module by concept.

No test functions live here, and no module here imports a test module or conftest.py. Test
files import these as ``helpers.<module>`` (pyproject.toml puts tests/ on sys.path for pytest;
a test's child process gets it through PYTHONPATH, helpers.child_env).
"""
