"""Parameter sets: kinds (schema with units), built-in sets (YAML package data), resolution."""
