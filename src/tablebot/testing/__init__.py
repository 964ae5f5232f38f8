"""Generators for tests and benchmarks: random tables and recorded inputs."""
