"""File formats: each one's reader and writer side by side (tables, robot and world TOML, inputs, ROBO Pro)."""
