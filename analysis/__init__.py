"""Collision outcome analysis: fragments, growth efficiency, compression, energy partition."""
