"""Sources of the project's FMUs: thin pythonfmu adapters over blocks/ and systems/."""
