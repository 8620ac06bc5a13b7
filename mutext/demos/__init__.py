"""Demonstrations run by ``mutext demo NAME``."""
