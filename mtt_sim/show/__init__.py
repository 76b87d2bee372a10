"""Pictures: the overlays render() draws on a frame, video files and the live viewer."""
