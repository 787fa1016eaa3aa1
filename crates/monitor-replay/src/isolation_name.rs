//! What the isolation names ([`IsolationName`]) and when it named it ([`NameGiven`]): the
//! words the isolation's tracker, its events and the reports share (below all three).

use monitor_core::isolation::Named;
use monitor_core::Fault;
use serde::{Serialize, Serializer};
use std::fmt;

/// What the isolation names, as the reports say it: one fault, or the friction class
/// (`b/bl`: B and Bl scale the same term of the torque balance and cannot be separated,
/// and to the paper's model a load change is a Bl change). Serialised as its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum IsolationName {
    /// One fault (never B or Bl alone: they are the friction class).
    Fault(Fault),
    /// The friction class B/Bl.
    Friction,
}

impl IsolationName {
    /// The name the isolation should give for `fault`: its own, the friction class for B
    /// and Bl.
    pub fn expected(fault: Fault) -> Self {
        match fault {
            Fault::B | Fault::Bl => IsolationName::Friction,
            f => IsolationName::Fault(f),
        }
    }

    /// The name of the core's conclusion.
    pub fn of(named: &Named) -> Self {
        match named {
            Named::Fault(c) => IsolationName::Fault(c.fault),
            Named::Friction { .. } => IsolationName::Friction,
        }
    }

    /// The fault's name ([`Fault::name`]) or `b/bl`.
    pub fn name(self) -> &'static str {
        match self {
            IsolationName::Fault(f) => f.name(),
            IsolationName::Friction => "b/bl",
        }
    }

    /// The name back from its text ([`IsolationName::name`]); `None` for any other text.
    pub fn from_name(s: &str) -> Option<Self> {
        if s == "b/bl" {
            Some(IsolationName::Friction)
        } else {
            Fault::from_name(s).map(IsolationName::Fault)
        }
    }
}

impl fmt::Display for IsolationName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for IsolationName {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// A name the isolation gave, with the first time it gave it [s]. Serialised as the pair
/// `[name, t_s]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NameGiven {
    /// What was named.
    pub name: IsolationName,
    /// When it was first named [s] (the replay's time, or as the caller shifts it).
    pub t_s: f64,
}

impl Serialize for NameGiven {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        (self.name, self.t_s).serialize(s)
    }
}
