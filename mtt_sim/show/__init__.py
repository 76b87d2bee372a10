"""Pictures: overlays on frames, videos, the live viewer and the documentation site."""
