//! Fieldless status enums that travel as one byte (wire frames, telemetry,
//! logs): one macro gives each its `repr(u8)` codes, `code()` and the
//! checked inverse `from_code()`, so no reader keeps its own table.

/// Declares a `Copy` + `Default` enum with explicit `u8` codes and its
/// `code`/`from_code` pair. Mark the default variant `#[default]`.
macro_rules! coded_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $( $(#[$vmeta:meta])* $variant:ident = $code:literal, )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
        #[repr(u8)]
        pub enum $name {
            $( $(#[$vmeta])* $variant = $code, )+
        }

        impl $name {
            /// The numeric code (`repr(u8)`).
            #[must_use]
            pub fn code(self) -> u8 {
                self as u8
            }

            /// The variant with this code, `None` for an unknown code.
            #[must_use]
            pub fn from_code(code: u8) -> Option<Self> {
                match code {
                    $( $code => Some(Self::$variant), )+
                    _ => None,
                }
            }
        }
    };
}
