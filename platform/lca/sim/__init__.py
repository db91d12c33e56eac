"""Physics layer: the G1, terrain, the composed scene and batched stepping."""
