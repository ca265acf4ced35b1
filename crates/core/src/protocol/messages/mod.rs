//! Typed message bodies, one file per message family (PROTOCOL.md section 3).

/// Declares a flag-byte newtype with one getter and one builder per bit, and `BITS`, the
/// same bits named for the frame describer (with any multi-bit groups after them): each
/// bit's meaning is written once.
macro_rules! flags {
    (
        $(#[$m:meta])*
        $name:ident {
            $( $(#[$fm:meta])* $get:ident / $set:ident = $bit:expr, $label:literal; )*
        }
        $( groups [ $($group:expr),* $(,)? ] )?
    ) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
        pub struct $name(pub u8);

        impl $name {
            /// Every named bit (then bit groups), for descriptions.
            pub(crate) const BITS: &'static [crate::protocol::fields::BitDef] = &[
                $( crate::protocol::fields::bit($bit, $label), )*
                $( $($group,)* )?
            ];

            $(
                $(#[$fm])*
                pub const fn $get(self) -> bool {
                    self.0 & (1 << $bit) != 0
                }

                #[doc = concat!("This value with `", stringify!($get), "` set to `on`.")]
                pub const fn $set(self, on: bool) -> Self {
                    if on { Self(self.0 | (1 << $bit)) } else { Self(self.0 & !(1 << $bit)) }
                }
            )*
        }
    };
}

pub mod basic;
pub mod coords;
pub mod motion;
pub mod positions;
pub mod programs;
pub mod scara;
pub mod scara_status;
pub mod signals;
pub mod status;
pub mod zones;
