"""Static and exhaustive analysis of a table: findings, properties, generated tests and diagrams."""
