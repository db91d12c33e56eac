"""The config layer's error: a bad value, its message starting with the full key."""


class ConfigValueError(ValueError):
    """A config value outside its allowed range; the message starts with the full key."""
