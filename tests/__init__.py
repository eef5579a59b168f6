"""The tests of epc_fast: a folder per subpackage of python/epc_fast, a file per module or
property; what they share is in helpers/."""
