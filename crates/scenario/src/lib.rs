//! Scenario files: TOML schemas, validation with located errors, conversion into workflow inputs.
