"""The Python drivers CTest runs (tests/CMakeLists.txt) and the helpers they
share (run_folder): a package, run from the top folder as
`python3 -m tests.NAME ARGS`, so that a driver imports `tests.run_folder`."""
