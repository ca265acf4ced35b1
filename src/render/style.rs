//! Colours, line widths and text sizes per role, for the dark and the light theme. Both
//! painters take their looks from here, so the window and the PNG agree.

use super::scene::Role;

/// A colour, not premultiplied: red, green, blue, alpha.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgba(pub [u8; 4]);

impl Rgba {
    pub const fn rgb(r: u8, g: u8, b: u8) -> Self {
        Rgba([r, g, b, 255])
    }
    pub const fn with_alpha(r: u8, g: u8, b: u8, a: u8) -> Self {
        Rgba([r, g, b, a])
    }
    /// The same colour with its alpha multiplied by `f` (0..=1).
    pub fn fade(self, f: f32) -> Self {
        let [r, g, b, a] = self.0;
        Rgba([r, g, b, (f32::from(a) * f.clamp(0.0, 1.0)).round() as u8])
    }
}

/// How one role is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Style {
    /// Outline colour and width (px); `None`: no outline.
    pub stroke: Option<(Rgba, f32)>,
    /// Fill colour of closed shapes; `None`: not filled.
    pub fill: Option<Rgba>,
    /// Dashed outline.
    pub dashed: bool,
    /// Text colour and size (px).
    pub text: (Rgba, f32),
}

/// The looks of a whole scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Palette {
    pub background: Rgba,
    pub dark: bool,
}

impl Palette {
    pub fn dark() -> Self {
        Palette {
            background: Rgba::rgb(24, 27, 32),
            dark: true,
        }
    }

    pub fn light() -> Self {
        Palette {
            background: Rgba::rgb(248, 249, 251),
            dark: false,
        }
    }

    pub fn for_theme(dark: bool) -> Self {
        if dark { Self::dark() } else { Self::light() }
    }

    /// Pick the dark- or light-theme value.
    fn pick<T>(&self, dark: T, light: T) -> T {
        if self.dark { dark } else { light }
    }

    /// The style of a role in this palette.
    pub fn style(&self, role: Role) -> Style {
        let text = self.pick(Rgba::rgb(214, 220, 228), Rgba::rgb(40, 46, 56));
        let muted = self.pick(Rgba::rgb(140, 150, 164), Rgba::rgb(96, 104, 118));
        let plain = Style {
            stroke: None,
            fill: None,
            dashed: false,
            text: (muted, 12.0),
        };
        let stroke = |c: Rgba, w: f32| Some((c, w));
        match role {
            Role::Grid => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(38, 43, 51), Rgba::rgb(226, 229, 235)),
                    1.0,
                ),
                ..plain
            },
            Role::EnvelopeRight => Style {
                stroke: stroke(
                    self.pick(
                        Rgba::with_alpha(88, 150, 230, 150),
                        Rgba::with_alpha(40, 100, 190, 150),
                    ),
                    1.0,
                ),
                fill: Some(self.pick(
                    Rgba::with_alpha(70, 130, 220, 34),
                    Rgba::with_alpha(60, 120, 220, 30),
                )),
                text: (
                    self.pick(Rgba::rgb(120, 170, 240), Rgba::rgb(30, 90, 180)),
                    12.0,
                ),
                ..plain
            },
            Role::EnvelopeLeft => Style {
                stroke: stroke(
                    self.pick(
                        Rgba::with_alpha(80, 190, 160, 150),
                        Rgba::with_alpha(20, 140, 110, 150),
                    ),
                    1.0,
                ),
                fill: Some(self.pick(
                    Rgba::with_alpha(60, 180, 150, 30),
                    Rgba::with_alpha(30, 160, 120, 28),
                )),
                text: (
                    self.pick(Rgba::rgb(110, 205, 175), Rgba::rgb(15, 120, 95)),
                    12.0,
                ),
                ..plain
            },
            Role::EnvelopeEdge => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(120, 132, 150), Rgba::rgb(120, 128, 142)),
                    1.5,
                ),
                ..plain
            },
            Role::Singular => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(230, 170, 60), Rgba::rgb(200, 130, 20)),
                    1.5,
                ),
                dashed: true,
                text: (
                    self.pick(Rgba::rgb(230, 170, 60), Rgba::rgb(170, 105, 10)),
                    11.0,
                ),
                ..plain
            },
            Role::LimitSector => Style {
                stroke: stroke(
                    self.pick(
                        Rgba::with_alpha(230, 90, 90, 200),
                        Rgba::with_alpha(200, 50, 50, 200),
                    ),
                    1.0,
                ),
                fill: Some(self.pick(
                    Rgba::with_alpha(220, 70, 70, 50),
                    Rgba::with_alpha(220, 60, 60, 40),
                )),
                text: (
                    self.pick(Rgba::rgb(235, 120, 120), Rgba::rgb(180, 40, 40)),
                    11.0,
                ),
                ..plain
            },
            Role::Base => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(150, 160, 175), Rgba::rgb(90, 98, 112)),
                    1.5,
                ),
                fill: Some(self.pick(Rgba::rgb(58, 64, 74), Rgba::rgb(200, 205, 214))),
                ..plain
            },
            Role::Link => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(200, 210, 225), Rgba::rgb(50, 60, 78)),
                    1.5,
                ),
                fill: Some(self.pick(Rgba::rgb(96, 108, 128), Rgba::rgb(150, 162, 182))),
                ..plain
            },
            Role::Joint => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(230, 236, 244), Rgba::rgb(40, 46, 56)),
                    1.5,
                ),
                fill: Some(self.pick(Rgba::rgb(44, 50, 60), Rgba::rgb(236, 239, 244))),
                ..plain
            },
            Role::Tool => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(255, 200, 60), Rgba::rgb(200, 120, 0)),
                    2.5,
                ),
                fill: Some(self.pick(Rgba::rgb(255, 200, 60), Rgba::rgb(220, 140, 0))),
                text: (
                    self.pick(Rgba::rgb(255, 210, 90), Rgba::rgb(160, 95, 0)),
                    12.0,
                ),
                ..plain
            },
            Role::FrameBase => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(170, 180, 195), Rgba::rgb(80, 88, 100)),
                    2.0,
                ),
                text: (
                    self.pick(Rgba::rgb(190, 198, 210), Rgba::rgb(60, 66, 78)),
                    12.0,
                ),
                ..plain
            },
            Role::FrameWork => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(190, 130, 255), Rgba::rgb(130, 60, 200)),
                    2.0,
                ),
                text: (
                    self.pick(Rgba::rgb(200, 150, 255), Rgba::rgb(110, 45, 180)),
                    12.0,
                ),
                ..plain
            },
            Role::FrameTool => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(255, 170, 90), Rgba::rgb(210, 100, 20)),
                    2.0,
                ),
                text: (
                    self.pick(Rgba::rgb(255, 180, 110), Rgba::rgb(180, 80, 10)),
                    12.0,
                ),
                ..plain
            },
            Role::FrameOverlay => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(100, 200, 230), Rgba::rgb(20, 130, 170)),
                    1.5,
                ),
                text: (
                    self.pick(Rgba::rgb(120, 210, 235), Rgba::rgb(15, 110, 150)),
                    11.0,
                ),
                ..plain
            },
            Role::GhostReachable => self.ghost(Rgba::rgb(80, 210, 120), Rgba::rgb(20, 150, 60)),
            Role::GhostFlip => self.ghost(Rgba::rgb(245, 175, 50), Rgba::rgb(200, 120, 0)),
            Role::GhostRefused => self.ghost(Rgba::rgb(245, 90, 90), Rgba::rgb(200, 30, 30)),
            Role::CpLine => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(90, 210, 240), Rgba::rgb(0, 140, 180)),
                    2.0,
                ),
                dashed: true,
                ..plain
            },
            Role::Zone => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(225, 150, 70), Rgba::rgb(190, 105, 20)),
                    1.5,
                ),
                fill: Some(self.pick(
                    Rgba::with_alpha(225, 150, 70, 36),
                    Rgba::with_alpha(210, 120, 30, 30),
                )),
                dashed: true,
                text: (
                    self.pick(Rgba::rgb(235, 170, 100), Rgba::rgb(160, 85, 10)),
                    12.0,
                ),
            },
            Role::ZoneEntered => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(245, 90, 90), Rgba::rgb(200, 30, 30)),
                    2.5,
                ),
                fill: Some(self.pick(
                    Rgba::with_alpha(245, 90, 90, 70),
                    Rgba::with_alpha(220, 40, 40, 55),
                )),
                dashed: false,
                text: (
                    self.pick(Rgba::rgb(255, 120, 110), Rgba::rgb(200, 30, 30)),
                    13.0,
                ),
            },
            Role::Marker => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(120, 200, 255), Rgba::rgb(20, 110, 190)),
                    1.5,
                ),
                text: (
                    self.pick(Rgba::rgb(150, 210, 255), Rgba::rgb(20, 95, 170)),
                    11.0,
                ),
                ..plain
            },
            Role::MarkerSelected => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(255, 240, 120), Rgba::rgb(170, 120, 0)),
                    2.5,
                ),
                text: (
                    self.pick(Rgba::rgb(255, 240, 140), Rgba::rgb(140, 95, 0)),
                    13.0,
                ),
                ..plain
            },
            Role::Trail => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(236, 100, 200), Rgba::rgb(190, 40, 150)),
                    2.0,
                ),
                ..plain
            },
            Role::Gauge => Style {
                stroke: stroke(muted, 1.5),
                fill: Some(self.pick(Rgba::rgb(36, 40, 48), Rgba::rgb(232, 235, 240))),
                text: (muted, 11.0),
                ..plain
            },
            Role::GaugeValue => Style {
                stroke: stroke(
                    self.pick(Rgba::rgb(255, 200, 60), Rgba::rgb(200, 120, 0)),
                    2.5,
                ),
                fill: Some(self.pick(
                    Rgba::with_alpha(255, 200, 60, 140),
                    Rgba::with_alpha(220, 140, 0, 120),
                )),
                text: (text, 12.0),
                ..plain
            },
            Role::Label => Style {
                text: (text, 12.0),
                ..plain
            },
            Role::Warning => Style {
                text: (
                    self.pick(Rgba::rgb(255, 120, 110), Rgba::rgb(200, 30, 30)),
                    14.0,
                ),
                ..plain
            },
        }
    }

    fn ghost(&self, dark: Rgba, light: Rgba) -> Style {
        let c = self.pick(dark, light);
        Style {
            stroke: Some((c, 2.0)),
            fill: Some(c.fade(0.22)),
            dashed: false,
            text: (c, 13.0),
        }
    }
}
