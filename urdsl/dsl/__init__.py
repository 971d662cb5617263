"""Python DSL that builds URScript syntax trees."""
