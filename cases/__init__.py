"""The cases' Python: the study runner, the measures, the reports. Run its
scripts from the repository's top folder as modules, e.g.
`/usr/bin/python3 -m cases.study cases/terzaghi/study.toml`."""
