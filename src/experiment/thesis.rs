//! The thesis' own numbers (Goldberg 1984, tables 5-10), as printed.

/// A cell of a thesis table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum T {
    /// A number.
    V(f64),
    /// No run ("-").
    No,
    /// Memory overflow on the Dolphin ("mo").
    Mo,
}
use T::{Mo, No, V};

impl T {
    /// The number, if any.
    pub fn value(self) -> Option<f64> {
        match self {
            V(x) => Some(x),
            _ => None,
        }
    }

    /// As printed.
    pub fn text(self) -> String {
        match self {
            V(x) => format!("{x}"),
            No => "-".into(),
            Mo => "mo".into(),
        }
    }

    /// For JSON.
    pub fn json(self) -> serde_json::Value {
        match self {
            V(x) => x.into(),
            No => serde_json::Value::Null,
            Mo => "mo".into(),
        }
    }
}

/// Table 5: messages; columns no sectors, sizes 200, 150, 100, 50, 25.
pub const TABLE5: [(usize, [T; 6]); 4] = [
    (4, [V(632.0), No, No, V(1001.0), V(1627.0), V(3445.0)]),
    (
        16,
        [V(4936.0), V(7677.0), No, V(5366.0), V(6549.0), V(11831.0)],
    ),
    (36, [V(17313.0), No, V(13942.0), V(11492.0), V(13837.0), No]),
    (64, [Mo, No, No, V(17801.0), V(21330.0), Mo]),
];

/// Table 6: elapsed seconds on the Dolphin; columns as table 5.
pub const TABLE6: [(usize, [T; 6]); 4] = [
    (4, [V(580.0), No, No, V(1114.0), V(1807.0), V(4086.0)]),
    (
        16,
        [V(4540.0), V(5956.0), No, V(5562.0), V(8426.0), V(18564.0)],
    ),
    (36, [V(38575.0), No, V(15926.0), V(13097.0), V(20234.0), No]),
    (64, [Mo, No, No, V(36256.0), V(68843.0), Mo]),
];

/// Table 7: balls, mean and sd of messages, mean and sd of elapsed seconds (non-sectored,
/// several seeds).
pub const TABLE7: [(usize, [f64; 4]); 3] = [
    (4, [452.0, 109.0, 545.0, 55.0]),
    (16, [3850.0, 708.0, 3536.0, 612.0]),
    (36, [14293.0, 1412.0, 26336.0, 5903.0]),
];

/// Table 8 (36 balls): message type and counts for no sectors and sizes 150, 100, 50.
pub const TABLE8: [(&str, [T; 4]); 6] = [
    ("SectorDeparture", [No, V(1080.0), V(1206.0), V(1952.0)]),
    ("SectorEntry", [No, V(480.0), V(680.0), V(1282.0)]),
    ("VelocityChange", [No, V(341.0), V(373.0), V(609.0)]),
    ("Collision", [V(2880.0), V(1746.0), V(1280.0), V(1070.0)]),
    ("Cancel", [V(2304.0), V(2616.0), V(2404.0), V(3092.0)]),
    ("NewVelocity", [V(12129.0), V(7679.0), V(5549.0), V(5832.0)]),
];

/// Table 9 (36 balls; 4, 9, 36 sectors): VelocityChange, estimated sector entries, sectors
/// occupied by a ball, estimated balls per sector, estimated and actual NewVelocity.
pub const TABLE9: [[f64; 6]; 3] = [
    [341.0, 155.0, 1.23, 11.0, 7459.0, 7679.0],
    [373.0, 232.0, 1.34, 5.4, 5671.0, 5549.0],
    [609.0, 465.0, 2.19, 2.2, 6648.0, 5832.0],
];
/// Table 9's parameters: total free path, number of collisions, table side.
pub const TABLE9_PARAMS: (f64, f64, f64) = (7749.0, 278.0, 600.0);

/// Table 10: messages by balls per sector 16, 9, 4, 1, 1/4 (note 5368 where table 5 has
/// 5366).
pub const TABLE10: [(usize, [T; 5]); 4] = [
    (4, [No, No, V(1001.0), V(1627.0), V(3445.0)]),
    (16, [V(7677.0), No, V(5368.0), V(6549.0), V(11831.0)]),
    (36, [No, V(13942.0), V(11492.0), V(13837.0), No]),
    (64, [No, No, V(17801.0), V(21330.0), Mo]),
];

/// Row `n` of a table keyed by balls.
pub fn row<const C: usize>(table: &[(usize, [T; C])], n: usize) -> [T; C] {
    table
        .iter()
        .find(|r| r.0 == n)
        .map(|r| r.1)
        .unwrap_or([No; C])
}
