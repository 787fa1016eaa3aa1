//! The identity of an effect or a law: its name, open to names the library does not know.
//!
//! The library's effects have the names of [`EffectKind`] (`thermal_drift`, `windage`, ...);
//! a user's law has the name its law file gives it (`compressor`). Both are an [`EffectId`]:
//! a name, compared as text, ordered with the library's effects first (in the library's
//! order) and the users' after them (by name), printed and serialised as the name.
//!
//! An [`EffectId`] is `Copy`: a name met for the first time is kept for the life of the
//! process ([`intern`]), once per distinct text, so a process that reads the same law file a
//! thousand times keeps its names once.

use monitor_core::EffectKind;
use std::collections::BTreeSet;
use std::sync::{Mutex, OnceLock};

/// The text `s` as a `&'static str`: the library's names as they are, any other text kept
/// once for the life of the process (the same text gives the same reference).
pub fn intern(s: &str) -> &'static str {
    if let Some(k) = EffectKind::from_name(s) {
        return k.name();
    }
    static NAMES: OnceLock<Mutex<BTreeSet<&'static str>>> = OnceLock::new();
    let names = NAMES.get_or_init(|| Mutex::new(BTreeSet::new()));
    // A poisoned lock only means another thread panicked while inserting a name: the set
    // itself is still a valid set of names.
    let mut names = names.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(&n) = names.get(s) {
        return n;
    }
    let n: &'static str = Box::leak(s.to_owned().into_boxed_str());
    names.insert(n);
    n
}

/// An effect's or a law's identity: its name (module doc).
#[derive(Clone, Copy)]
pub struct EffectId(&'static str);

impl EffectId {
    /// `thermal_drift` ([`EffectKind::ThermalDrift`]).
    pub const THERMAL_DRIFT: EffectId = EffectId::library(EffectKind::ThermalDrift);
    /// `saturation` ([`EffectKind::Saturation`]).
    pub const SATURATION: EffectId = EffectId::library(EffectKind::Saturation);
    /// `iron_loss` ([`EffectKind::IronLoss`]).
    pub const IRON_LOSS: EffectId = EffectId::library(EffectKind::IronLoss);
    /// `coulomb_friction` ([`EffectKind::CoulombFriction`]).
    pub const COULOMB_FRICTION: EffectId = EffectId::library(EffectKind::CoulombFriction);
    /// `windage` ([`EffectKind::Windage`]).
    pub const WINDAGE: EffectId = EffectId::library(EffectKind::Windage);
    /// `load_torque` ([`EffectKind::LoadTorque`]).
    pub const LOAD_TORQUE: EffectId = EffectId::library(EffectKind::LoadTorque);
    /// `supply_unbalance` ([`EffectKind::SupplyUnbalance`]).
    pub const SUPPLY_UNBALANCE: EffectId = EffectId::library(EffectKind::SupplyUnbalance);
    /// `phase_asymmetry` ([`EffectKind::PhaseAsymmetry`]).
    pub const PHASE_ASYMMETRY: EffectId = EffectId::library(EffectKind::PhaseAsymmetry);
    /// `flux_dynamics` ([`EffectKind::FluxDynamics`]).
    pub const FLUX_DYNAMICS: EffectId = EffectId::library(EffectKind::FluxDynamics);
    /// `current_dynamics` ([`EffectKind::CurrentDynamics`]).
    pub const CURRENT_DYNAMICS: EffectId = EffectId::library(EffectKind::CurrentDynamics);
    /// `rotor_asymmetry` ([`EffectKind::RotorAsymmetry`]).
    pub const ROTOR_ASYMMETRY: EffectId = EffectId::library(EffectKind::RotorAsymmetry);
    /// `d_axis_dynamics` ([`EffectKind::DAxisDynamics`]).
    pub const D_AXIS_DYNAMICS: EffectId = EffectId::library(EffectKind::DAxisDynamics);
    /// `cross_coupling_dynamics` ([`EffectKind::CrossCouplingDynamics`]).
    pub const CROSS_COUPLING_DYNAMICS: EffectId =
        EffectId::library(EffectKind::CrossCouplingDynamics);

    /// The library effect `kind`.
    pub const fn library(kind: EffectKind) -> EffectId {
        EffectId(kind.name())
    }

    /// An effect of the library that has no [`EffectKind`] (a law added to the library after
    /// the core's list): its name as a constant.
    pub const fn from_static(name: &'static str) -> EffectId {
        EffectId(name)
    }

    /// The effect or law named `name` (a library name gives the library's effect).
    pub fn named(name: &str) -> EffectId {
        EffectId(intern(name))
    }

    /// The name (the JSON's and the command line's).
    pub fn name(self) -> &'static str {
        self.0
    }

    /// The library's effect of this name, `None` for a user's law.
    pub fn kind(self) -> Option<EffectKind> {
        EffectKind::from_name(self.0)
    }

    /// True for one of the library's effects.
    pub fn is_library(self) -> bool {
        self.kind().is_some()
    }

    /// True for the model's own simplifications (the library's dynamics effects,
    /// [`EffectKind::is_dynamics`]); a user's law never is one.
    pub fn is_dynamics(self) -> bool {
        self.kind().is_some_and(EffectKind::is_dynamics)
    }

    /// The sort key: the library's effects in the library's order, then the users' by name.
    fn key(self) -> (usize, &'static str) {
        let i = EffectKind::ALL
            .iter()
            .position(|k| k.name() == self.0)
            .unwrap_or(EffectKind::ALL.len());
        (i, self.0)
    }
}

impl From<EffectKind> for EffectId {
    fn from(kind: EffectKind) -> Self {
        EffectId::library(kind)
    }
}

impl PartialEq for EffectId {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.0, other.0) || self.0 == other.0
    }
}

impl Eq for EffectId {}

impl PartialEq<EffectKind> for EffectId {
    fn eq(&self, other: &EffectKind) -> bool {
        self.0 == other.name()
    }
}

impl PartialEq<EffectId> for EffectKind {
    fn eq(&self, other: &EffectId) -> bool {
        other == self
    }
}

impl std::hash::Hash for EffectId {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.0.hash(state);
    }
}

impl PartialOrd for EffectId {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for EffectId {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.key().cmp(&other.key())
    }
}

impl std::fmt::Display for EffectId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0)
    }
}

impl std::fmt::Debug for EffectId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "EffectId({})", self.0)
    }
}

impl serde::Serialize for EffectId {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.0)
    }
}

impl<'de> serde::Deserialize<'de> for EffectId {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        Ok(EffectId::named(&s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn library_names_are_the_library_effects_and_users_names_follow() {
        for k in EffectKind::ALL {
            let id = EffectId::named(k.name());
            assert_eq!(id, k);
            assert_eq!(id.kind(), Some(k));
            assert_eq!(id, EffectId::from(k));
        }
        let user = EffectId::named("compressor");
        assert_eq!(user.kind(), None);
        assert!(!user.is_dynamics() && !user.is_library());
        assert_eq!(user, EffectId::named(&String::from("compressor")));
        assert_ne!(user, EffectId::named("pump"));
        // The library's order first, the users' by name after it.
        let mut v = [
            EffectId::named("pump"),
            EffectId::library(EffectKind::CrossCouplingDynamics),
            user,
            EffectId::library(EffectKind::ThermalDrift),
        ];
        v.sort();
        let names: Vec<&str> = v.iter().map(|e| e.name()).collect();
        assert_eq!(
            names,
            [
                "thermal_drift",
                "cross_coupling_dynamics",
                "compressor",
                "pump"
            ]
        );
    }

    #[test]
    fn a_name_is_kept_once() {
        let a = intern("a law read twice");
        let b = intern(&format!("a law {} twice", "read"));
        assert!(std::ptr::eq(a, b));
    }

    #[test]
    fn serialises_as_its_name() {
        let v = serde_json_like(EffectId::named("compressor"));
        assert_eq!(v, "compressor");
    }

    /// The name a serializer writes (through TOML's value serializer, to stay within this
    /// crate's dependencies).
    fn serde_json_like(id: EffectId) -> String {
        #[derive(serde::Serialize)]
        struct W {
            id: EffectId,
        }
        let s = toml::to_string(&W { id }).unwrap_or_default();
        s.trim()
            .trim_start_matches("id = ")
            .trim_matches('"')
            .to_string()
    }
}
