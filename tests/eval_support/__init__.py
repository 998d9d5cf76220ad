"""Test doubles for the evaluation harness: a fake environment and a fake OpenAI server."""
