"""Robot execution (SPEC §5): a simulated joint, controllers, what was played, validation and export."""
