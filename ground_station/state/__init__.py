"""What a control cycle carries to the next: estimates, commands, roles. Imports: nothing."""
