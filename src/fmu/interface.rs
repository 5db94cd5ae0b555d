//! Which FMI interfaces an FMU declares (`fxbody pack --interface cs|me|both`):
//! co-simulation (the body steps itself, the default), Model Exchange (the master
//! integrates the body's continuous states with its own solver) or both in one FMU. The
//! choice is part of the resources (`interface` in scene.txt), since a Model Exchange FMU
//! has more variables (the continuous states and their derivatives) than a co-simulation
//! one, and the library must serve the variables its description lists.

/// The interfaces an FMU declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interfaces {
    /// Co-simulation only (the default).
    #[default]
    CoSimulation,
    /// Model Exchange only.
    ModelExchange,
    /// Both, in one model description.
    Both,
}

impl Interfaces {
    /// The interfaces named by `pack --interface` and scene.txt: `cs`, `me` or `both`.
    pub fn parse(s: &str) -> Option<Interfaces> {
        match s.trim() {
            "cs" => Some(Interfaces::CoSimulation),
            "me" => Some(Interfaces::ModelExchange),
            "both" => Some(Interfaces::Both),
            _ => None,
        }
    }

    /// The name [`Interfaces::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Interfaces::CoSimulation => "cs",
            Interfaces::ModelExchange => "me",
            Interfaces::Both => "both",
        }
    }

    /// Whether co-simulation is declared.
    pub fn co_simulation(self) -> bool {
        self != Interfaces::ModelExchange
    }

    /// Whether Model Exchange is declared.
    pub fn model_exchange(self) -> bool {
        self != Interfaces::CoSimulation
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for i in [
            Interfaces::CoSimulation,
            Interfaces::ModelExchange,
            Interfaces::Both,
        ] {
            assert_eq!(Interfaces::parse(i.name()), Some(i));
        }
        assert_eq!(Interfaces::parse("cosim"), None);
        assert!(Interfaces::Both.co_simulation() && Interfaces::Both.model_exchange());
        assert!(!Interfaces::ModelExchange.co_simulation());
        assert!(!Interfaces::CoSimulation.model_exchange());
    }
}
