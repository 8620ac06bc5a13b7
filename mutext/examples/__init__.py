"""Thesis examples shared by the book, demos, exercises and tests."""
