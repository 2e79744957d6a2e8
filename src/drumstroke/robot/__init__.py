"""Robot execution: a simulated joint, controllers, what was played, validation and export."""
