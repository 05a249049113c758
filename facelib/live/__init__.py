"""Live sessions: text, audio and cues as they arrive -> frames at a fixed rate with a
bounded look-ahead, by the offline generators and rules (see ``docs/live.md``)."""
