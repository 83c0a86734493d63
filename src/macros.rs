//! Small macros that keep repeated shapes in one place: option setters and enums named by
//! strings (one table of names per enum for Display, FromStr and serde).

/// `impl Default` that returns the type's `DEFAULT` constant (options keep their defaults in a
/// `const` so that other constants can build on them).
macro_rules! default_is_const {
    ($ty:ident) => {
        impl Default for $ty {
            fn default() -> Self {
                $ty::DEFAULT
            }
        }
    };
}

/// `with_*` setters of an options struct, one line each: `name(arg: Type) => |s| s.field;`
/// sets that place of `self` to `arg`; `name(a: A, b: B) => |s| s.x, s.y;` sets two places at
/// once. Several types may share one list, written
/// `setters!([A, B] { ... })` (options that embed the same part reach it through one path).
macro_rules! setters {
    ([$($ty:ident),+] $body:tt) => {
        $(setters!($ty $body);)+
    };
    ($ty:ident { $($(#[$doc:meta])* $name:ident($($arg:ident: $t:ty),+) => |$s:ident| $($place:expr),+;)* }) => {
        impl $ty {
            $($(#[$doc])*
            pub fn $name(mut self, $($arg: $t),+) -> Self {
                let $s = &mut self;
                $($place = $arg;)+
                self
            })*
        }
    };
}

/// Display, FromStr and serde for a field-less enum from one table of names:
/// `named_enum!(Type, "option", { Variant => "name" | "alias", ... })`. Parsing an unknown name
/// fails with `option <option>: '<name>' is not one of '<a>', '<b>', ...`.
macro_rules! named_enum {
    ($ty:ident, $option:literal, { $($variant:ident => $name:literal $(| $alias:literal)*),+ $(,)? }) => {
        impl $ty {
            /// Every value, in the order of the table of names.
            pub const ALL: &'static [$ty] = &[$($ty::$variant),+];

            /// The value's name, as options, reports and the command line spell it.
            pub const fn name(self) -> &'static str {
                match self {
                    $($ty::$variant => $name),+
                }
            }

            /// The value named `name` (or one of its aliases).
            pub fn from_name(name: &str) -> Option<$ty> {
                match name {
                    $($name $(| $alias)* => Some($ty::$variant),)+
                    _ => None,
                }
            }
        }

        impl std::fmt::Display for $ty {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl std::str::FromStr for $ty {
            type Err = String;
            fn from_str(s: &str) -> Result<$ty, String> {
                $ty::from_name(s).ok_or_else(|| {
                    let names: Vec<String> = $ty::ALL.iter().map(|v| format!("'{}'", v.name())).collect();
                    format!("option {}: '{}' is not one of {}", $option, s, names.join(", "))
                })
            }
        }

        impl serde::Serialize for $ty {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }

        impl<'de> serde::Deserialize<'de> for $ty {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<$ty, D::Error> {
                let s = String::deserialize(d)?;
                s.parse().map_err(serde::de::Error::custom)
            }
        }
    };
}
