"""Speaking characters: text or recorded speech → phones → visemes → AUs."""
