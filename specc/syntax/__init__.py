"""Text <-> model: parser, builder, friendly parse errors, printer."""
