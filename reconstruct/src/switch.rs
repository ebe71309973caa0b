//! Options that are off, on, or decided from the data (`"auto"`): written
//! as a name, or as `true`/`false` as they were before they had `"auto"`.

use serde::{Deserialize, Deserializer};

/// An option with an off and an on value among its names.
pub trait Switch: Sized {
    const OFF: Self;
    const ON: Self;
}

/// Reads a [`Switch`] as written: a name, or a flag
/// (`#[serde(deserialize_with = "flag_or_name")]`).
pub fn flag_or_name<'de, D, T>(d: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: Switch + Deserialize<'de>,
{
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Written<T> {
        Flag(bool),
        Named(T),
    }
    Ok(match Written::<T>::deserialize(d)? {
        Written::Flag(true) => T::ON,
        Written::Flag(false) => T::OFF,
        Written::Named(named) => named,
    })
}
