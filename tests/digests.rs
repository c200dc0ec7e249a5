//! Every built-in scenario and every hard case of `scenarios/` on every engine, against a table
//! of their final-state digests, event counts by kind and message counts by type. The table was
//! recorded with the `poolsim` command; a change that alters any entry changes the physics or the
//! message flow, and must say so.

use poolsim::engine::Ignore;
use poolsim::model::pool::NvDelay;
use poolsim::run::{execute, EngineKind, FixedNews, RunConfig, SectorChoice};
use poolsim::scenario::{builtin, load, Scenario};
use poolsim::summary::MessageKind;

mod common;

/// (scenario, engine, digest, events by kind: ball-ball ball-cushion ball-corner ball-pocket,
/// messages by type in `MessageKind::ALL` order, then the thesis' total).
const TABLE: &[(&str, &str, &str, &str, &str)] = &[
    (
        "plate1",
        "event-list",
        "914115053a071cac",
        "1 0 0 1",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "plate1",
        "time-step",
        "f777d0afa2e40fcf",
        "1 0 0 1",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "plate1",
        "objects",
        "914115053a071cac",
        "1 0 0 1",
        "44 6 2 0 0 0 0 0 0 0 0 52",
    ),
    (
        "plate1",
        "sectored",
        "914115053a071cac",
        "1 0 0 1",
        "44 6 6 3 0 4 2 0 0 0 2 63",
    ),
    (
        "plate1",
        "time-warp",
        "914115053a071cac",
        "1 0 0 1",
        "44 6 2 0 0 0 0 0 0 0 0 52",
    ),
    (
        "plate1",
        "time-warp-sectored",
        "914115053a071cac",
        "1 0 0 1",
        "44 6 6 3 0 4 2 0 0 0 2 63",
    ),
    (
        "gas",
        "event-list",
        "e854bc0dfd1a524c",
        "106 39 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "gas",
        "time-step",
        "02576cef4ed1c3ab",
        "105 38 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "gas",
        "objects",
        "e854bc0dfd1a524c",
        "106 39 0 0",
        "10563 2296 1764 0 0 0 0 0 0 0 0 14623",
    ),
    (
        "gas",
        "sectored",
        "e854bc0dfd1a524c",
        "106 39 0 0",
        "5056 1400 1936 302 464 722 36 0 0 0 212 9880",
    ),
    (
        "gas",
        "time-warp",
        "e854bc0dfd1a524c",
        "106 39 0 0",
        "10563 2296 1764 0 0 0 0 0 0 0 0 14623",
    ),
    (
        "gas",
        "time-warp-sectored",
        "e854bc0dfd1a524c",
        "106 39 0 0",
        "5056 1400 1936 302 464 722 36 0 0 0 212 9880",
    ),
    (
        "reversal",
        "event-list",
        "4f28c44116124e77",
        "28 17 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "reversal",
        "time-step",
        "a576cd529e7c8491",
        "28 17 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "reversal",
        "objects",
        "4f28c44116124e77",
        "28 17 0 0",
        "1571 632 484 0 0 0 0 0 0 0 0 2687",
    ),
    (
        "reversal",
        "sectored",
        "4f28c44116124e77",
        "28 17 0 0",
        "1571 632 630 73 0 178 16 0 0 0 56 3084",
    ),
    (
        "reversal",
        "time-warp",
        "4f28c44116124e77",
        "28 17 0 0",
        "1571 632 484 0 0 0 0 0 0 0 0 2687",
    ),
    (
        "reversal",
        "time-warp-sectored",
        "4f28c44116124e77",
        "28 17 0 0",
        "1571 632 630 73 0 178 16 0 0 0 56 3084",
    ),
    (
        "pool",
        "event-list",
        "a967047147c45c58",
        "74 97 2 3",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "pool",
        "time-step",
        "c6fe5b651a280df2",
        "54 65 1 5",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "pool",
        "objects",
        "a967047147c45c58",
        "74 97 2 3",
        "10254 898 510 0 0 0 0 0 0 0 0 11662",
    ),
    (
        "pool",
        "sectored",
        "a967047147c45c58",
        "74 97 2 3",
        "6967 850 980 258 110 566 16 0 0 0 148 9731",
    ),
    (
        "pool",
        "time-warp",
        "a967047147c45c58",
        "74 97 2 3",
        "10254 898 510 0 0 0 0 0 0 0 0 11662",
    ),
    (
        "pool",
        "time-warp-sectored",
        "a967047147c45c58",
        "74 97 2 3",
        "6967 850 980 258 110 566 16 0 0 0 148 9731",
    ),
    (
        "cradle",
        "event-list",
        "63b8983a46109ee5",
        "5 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "cradle",
        "time-step",
        "77a5d43ba287cabb",
        "5 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "cradle",
        "objects",
        "63b8983a46109ee5",
        "5 0 0 0",
        "129 42 30 0 0 0 0 0 0 0 0 201",
    ),
    (
        "cradle",
        "sectored",
        "63b8983a46109ee5",
        "5 0 0 0",
        "120 32 34 12 2 14 7 0 0 0 10 214",
    ),
    (
        "cradle",
        "time-warp",
        "63b8983a46109ee5",
        "5 0 0 0",
        "129 42 30 0 0 0 0 0 0 0 0 201",
    ),
    (
        "cradle",
        "time-warp-sectored",
        "63b8983a46109ee5",
        "5 0 0 0",
        "120 32 34 12 2 14 7 0 0 0 10 214",
    ),
    (
        "scenarios/along_cushion.toml",
        "event-list",
        "16268cce9abc9332",
        "0 1 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/along_cushion.toml",
        "time-step",
        "b5730df6e3a2ba99",
        "0 1 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/along_cushion.toml",
        "objects",
        "16268cce9abc9332",
        "0 1 0 0",
        "8 4 0 0 0 0 0 0 0 0 0 12",
    ),
    (
        "scenarios/along_cushion.toml",
        "sectored",
        "16268cce9abc9332",
        "0 1 0 0",
        "8 4 2 1 0 4 1 0 0 0 0 19",
    ),
    (
        "scenarios/along_cushion.toml",
        "time-warp",
        "16268cce9abc9332",
        "0 1 0 0",
        "8 4 0 0 0 0 0 0 0 0 0 12",
    ),
    (
        "scenarios/along_cushion.toml",
        "time-warp-sectored",
        "16268cce9abc9332",
        "0 1 0 0",
        "8 4 2 1 0 4 1 0 0 0 0 19",
    ),
    (
        "scenarios/corner_point.toml",
        "event-list",
        "77179200706dafc2",
        "0 0 1 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/corner_point.toml",
        "time-step",
        "9ab6da9527500d20",
        "0 0 1 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/corner_point.toml",
        "objects",
        "77179200706dafc2",
        "0 0 1 0",
        "16 6 2 0 0 0 0 0 0 0 0 24",
    ),
    (
        "scenarios/corner_point.toml",
        "sectored",
        "77179200706dafc2",
        "0 0 1 0",
        "16 6 4 1 0 4 1 0 0 0 0 31",
    ),
    (
        "scenarios/corner_point.toml",
        "time-warp",
        "77179200706dafc2",
        "0 0 1 0",
        "16 6 2 0 0 0 0 0 0 0 0 24",
    ),
    (
        "scenarios/corner_point.toml",
        "time-warp-sectored",
        "77179200706dafc2",
        "0 0 1 0",
        "16 6 4 1 0 4 1 0 0 0 0 31",
    ),
    (
        "scenarios/fig06_corner.toml",
        "event-list",
        "e13e72e535655744",
        "0 0 1 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig06_corner.toml",
        "time-step",
        "67b0aaa4f9461871",
        "0 0 1 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig06_corner.toml",
        "objects",
        "e13e72e535655744",
        "0 0 1 0",
        "16 6 2 0 0 0 0 0 0 0 0 24",
    ),
    (
        "scenarios/fig06_corner.toml",
        "sectored",
        "e13e72e535655744",
        "0 0 1 0",
        "16 6 4 1 0 4 1 0 0 0 0 31",
    ),
    (
        "scenarios/fig06_corner.toml",
        "time-warp",
        "e13e72e535655744",
        "0 0 1 0",
        "16 6 2 0 0 0 0 0 0 0 0 24",
    ),
    (
        "scenarios/fig06_corner.toml",
        "time-warp-sectored",
        "e13e72e535655744",
        "0 0 1 0",
        "16 6 4 1 0 4 1 0 0 0 0 31",
    ),
    (
        "scenarios/fig09_simultaneous.toml",
        "event-list",
        "8c1c4b6ac45a3984",
        "3 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig09_simultaneous.toml",
        "time-step",
        "fd451b60b8af6379",
        "3 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig09_simultaneous.toml",
        "objects",
        "8c1c4b6ac45a3984",
        "3 0 0 0",
        "64 18 8 0 0 0 0 0 0 0 0 90",
    ),
    (
        "scenarios/fig09_simultaneous.toml",
        "sectored",
        "8c1c4b6ac45a3984",
        "3 0 0 0",
        "64 18 14 6 0 10 4 0 0 0 6 112",
    ),
    (
        "scenarios/fig09_simultaneous.toml",
        "time-warp",
        "8c1c4b6ac45a3984",
        "3 0 0 0",
        "64 18 8 0 0 0 0 0 0 0 0 90",
    ),
    (
        "scenarios/fig09_simultaneous.toml",
        "time-warp-sectored",
        "8c1c4b6ac45a3984",
        "3 0 0 0",
        "64 18 14 6 0 10 4 0 0 0 6 112",
    ),
    (
        "scenarios/fig10_three_in_line.toml",
        "event-list",
        "33f67802d24b46d7",
        "3 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig10_three_in_line.toml",
        "time-step",
        "2924f0445994573c",
        "3 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig10_three_in_line.toml",
        "objects",
        "33f67802d24b46d7",
        "3 0 0 0",
        "51 24 14 0 0 0 0 0 0 0 0 89",
    ),
    (
        "scenarios/fig10_three_in_line.toml",
        "sectored",
        "33f67802d24b46d7",
        "3 0 0 0",
        "51 24 22 6 0 12 3 0 0 0 6 115",
    ),
    (
        "scenarios/fig10_three_in_line.toml",
        "time-warp",
        "33f67802d24b46d7",
        "3 0 0 0",
        "51 24 14 0 0 0 0 0 0 0 0 89",
    ),
    (
        "scenarios/fig10_three_in_line.toml",
        "time-warp-sectored",
        "33f67802d24b46d7",
        "3 0 0 0",
        "51 24 22 6 0 12 3 0 0 0 6 115",
    ),
    (
        "scenarios/fig11_three_ball.toml",
        "event-list",
        "bc257e18e44b5a8e",
        "2 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig11_three_ball.toml",
        "time-step",
        "f06eec05ae81c937",
        "2 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig11_three_ball.toml",
        "objects",
        "bc257e18e44b5a8e",
        "2 0 0 0",
        "39 20 12 0 0 0 0 0 0 0 0 71",
    ),
    (
        "scenarios/fig11_three_ball.toml",
        "sectored",
        "bc257e18e44b5a8e",
        "2 0 0 0",
        "39 20 18 4 0 10 3 0 0 0 4 91",
    ),
    (
        "scenarios/fig11_three_ball.toml",
        "time-warp",
        "bc257e18e44b5a8e",
        "2 0 0 0",
        "39 20 12 0 0 0 0 0 0 0 0 71",
    ),
    (
        "scenarios/fig11_three_ball.toml",
        "time-warp-sectored",
        "bc257e18e44b5a8e",
        "2 0 0 0",
        "39 20 18 4 0 10 3 0 0 0 4 91",
    ),
    (
        "scenarios/fig12_resting_on_cushion.toml",
        "event-list",
        "63ca1d05b10e96bd",
        "2 1 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig12_resting_on_cushion.toml",
        "time-step",
        "7a915e5b9629cf11",
        "2 1 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/fig12_resting_on_cushion.toml",
        "objects",
        "63ca1d05b10e96bd",
        "2 1 0 0",
        "34 12 4 0 0 0 0 0 0 0 0 50",
    ),
    (
        "scenarios/fig12_resting_on_cushion.toml",
        "sectored",
        "63ca1d05b10e96bd",
        "2 1 0 0",
        "34 12 10 5 0 8 2 0 0 0 4 69",
    ),
    (
        "scenarios/fig12_resting_on_cushion.toml",
        "time-warp",
        "63ca1d05b10e96bd",
        "2 1 0 0",
        "34 12 4 0 0 0 0 0 0 0 0 50",
    ),
    (
        "scenarios/fig12_resting_on_cushion.toml",
        "time-warp-sectored",
        "63ca1d05b10e96bd",
        "2 1 0 0",
        "34 12 10 5 0 8 2 0 0 0 4 69",
    ),
    (
        "scenarios/grazing.toml",
        "event-list",
        "558f4df994c3da35",
        "0 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/grazing.toml",
        "time-step",
        "c2387e67e37f88d8",
        "0 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/grazing.toml",
        "objects",
        "558f4df994c3da35",
        "0 0 0 0",
        "9 2 0 0 0 0 0 0 0 0 0 11",
    ),
    (
        "scenarios/grazing.toml",
        "sectored",
        "558f4df994c3da35",
        "0 0 0 0",
        "9 2 0 0 0 2 2 0 0 0 0 13",
    ),
    (
        "scenarios/grazing.toml",
        "time-warp",
        "558f4df994c3da35",
        "0 0 0 0",
        "9 2 0 0 0 0 0 0 0 0 0 11",
    ),
    (
        "scenarios/grazing.toml",
        "time-warp-sectored",
        "558f4df994c3da35",
        "0 0 0 0",
        "9 2 0 0 0 2 2 0 0 0 0 13",
    ),
    (
        "scenarios/plate7.toml",
        "event-list",
        "e8f417788acc3e29",
        "0 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/plate7.toml",
        "time-step",
        "6b912f5220121018",
        "0 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/plate7.toml",
        "objects",
        "e8f417788acc3e29",
        "0 0 0 0",
        "61 12 0 0 20 20 9 0 0 0 0 113",
    ),
    (
        "scenarios/plate7.toml",
        "sectored",
        "e8f417788acc3e29",
        "0 0 0 0",
        "49 24 0 0 0 12 7 0 0 0 0 85",
    ),
    (
        "scenarios/plate7.toml",
        "time-warp",
        "e8f417788acc3e29",
        "0 0 0 0",
        "61 12 0 0 20 20 9 0 0 0 0 113",
    ),
    (
        "scenarios/plate7.toml",
        "time-warp-sectored",
        "e8f417788acc3e29",
        "0 0 0 0",
        "49 24 0 0 0 12 7 0 0 0 0 85",
    ),
    (
        "scenarios/sandwich.toml",
        "event-list",
        "d9b31bd2ca045d6c",
        "3 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/sandwich.toml",
        "time-step",
        "a4f35654a7f6e969",
        "3 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/sandwich.toml",
        "objects",
        "d9b31bd2ca045d6c",
        "3 0 0 0",
        "51 24 14 0 0 0 0 0 0 0 0 89",
    ),
    (
        "scenarios/sandwich.toml",
        "sectored",
        "d9b31bd2ca045d6c",
        "3 0 0 0",
        "51 24 22 6 0 12 3 0 0 0 6 115",
    ),
    (
        "scenarios/sandwich.toml",
        "time-warp",
        "d9b31bd2ca045d6c",
        "3 0 0 0",
        "51 24 14 0 0 0 0 0 0 0 0 89",
    ),
    (
        "scenarios/sandwich.toml",
        "time-warp-sectored",
        "d9b31bd2ca045d6c",
        "3 0 0 0",
        "51 24 22 6 0 12 3 0 0 0 6 115",
    ),
    (
        "scenarios/sector_boundary.toml",
        "event-list",
        "1989906e42dc1c09",
        "1 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/sector_boundary.toml",
        "time-step",
        "ba350963e0752b66",
        "1 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/sector_boundary.toml",
        "objects",
        "1989906e42dc1c09",
        "1 0 0 0",
        "31 4 4 3 2 6 3 0 0 0 2 50",
    ),
    (
        "scenarios/sector_boundary.toml",
        "sectored",
        "1989906e42dc1c09",
        "1 0 0 0",
        "19 6 4 2 0 4 2 0 0 0 2 35",
    ),
    (
        "scenarios/sector_boundary.toml",
        "time-warp",
        "1989906e42dc1c09",
        "1 0 0 0",
        "31 4 4 3 2 6 3 0 0 0 2 50",
    ),
    (
        "scenarios/sector_boundary.toml",
        "time-warp-sectored",
        "1989906e42dc1c09",
        "1 0 0 0",
        "19 6 4 2 0 4 2 0 0 0 2 35",
    ),
    (
        "scenarios/touching_at_start.toml",
        "event-list",
        "ffd02bce25958bc6",
        "1 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/touching_at_start.toml",
        "time-step",
        "1b8d72e26ed1e838",
        "1 0 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "scenarios/touching_at_start.toml",
        "objects",
        "ffd02bce25958bc6",
        "1 0 0 0",
        "36 8 2 0 0 0 0 0 0 0 0 46",
    ),
    (
        "scenarios/touching_at_start.toml",
        "sectored",
        "ffd02bce25958bc6",
        "1 0 0 0",
        "36 8 4 2 0 6 4 0 0 0 2 56",
    ),
    (
        "scenarios/touching_at_start.toml",
        "time-warp",
        "ffd02bce25958bc6",
        "1 0 0 0",
        "36 8 2 0 0 0 0 0 0 0 0 46",
    ),
    (
        "scenarios/touching_at_start.toml",
        "time-warp-sectored",
        "ffd02bce25958bc6",
        "1 0 0 0",
        "36 8 4 2 0 6 4 0 0 0 2 56",
    ),
    // the implosion's balls run about 1,000 units per time unit: a time step of 0.001 would
    // let them pass through one another, so it has no time-step row
    (
        "implosion",
        "event-list",
        "d7a23568a0e20ac6",
        "4413 224 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "implosion",
        "objects",
        "d7a23568a0e20ac6",
        "4413 224 0 0",
        "3728550 245622 235394 0 0 0 0 0 0 0 0 4209566",
    ),
    (
        "implosion",
        "sectored",
        "d7a23568a0e20ac6",
        "4413 224 0 0",
        "3681718 228868 265864 9053 35502 24898 404 0 0 0 8828 4245903",
    ),
    (
        "implosion",
        "time-warp",
        "d7a23568a0e20ac6",
        "4413 224 0 0",
        "3728550 245622 235394 0 0 0 0 0 0 0 0 4209566",
    ),
    (
        "implosion",
        "time-warp-sectored",
        "d7a23568a0e20ac6",
        "4413 224 0 0",
        "3681718 228868 265864 9053 35502 24898 404 0 0 0 8828 4245903",
    ),
    // the disk fluid's start: 400 disks on a triangular lattice at 0.5, Maxwell velocities
    (
        "disks",
        "event-list",
        "1e55fabdf55dc08c",
        "7089 538 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "disks",
        "time-step",
        "ae8939796cfc6232",
        "7072 510 0 0",
        "0 0 0 0 0 0 0 0 0 0 0 0",
    ),
    (
        "disks",
        "objects",
        "1e55fabdf55dc08c",
        "7089 538 0 0",
        "6011948 454260 431746 0 0 0 0 0 0 0 0 6897954",
    ),
    (
        "disks",
        "sectored",
        "1e55fabdf55dc08c",
        "7089 538 0 0",
        "463072 99310 173644 22907 48424 48798 597 0 0 0 14180 856155",
    ),
    (
        "disks",
        "time-warp",
        "1e55fabdf55dc08c",
        "7089 538 0 0",
        "6011948 454260 431746 0 0 0 0 0 0 0 0 6897954",
    ),
    (
        "disks",
        "time-warp-sectored",
        "1e55fabdf55dc08c",
        "7089 538 0 0",
        "463072 99310 173644 22907 48424 48798 597 0 0 0 14180 856155",
    ),
];

fn scenario(name: &str) -> Scenario {
    let path = format!("{}/{name}", env!("CARGO_MANIFEST_DIR"));
    let spec = if name.ends_with(".toml") { &path } else { name };
    load(spec, &builtin::Params::default()).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The engine `name` as the command line gives it: `objects` and `time-warp` take the
/// scenario's own sectors when it has them.
fn engine(name: &str, s: &Scenario) -> EngineKind {
    let own = s.sectors.as_ref().map(|_| SectorChoice::Scenario);
    let tw = common::two_workers;
    match name {
        "event-list" => EngineKind::EventList,
        "time-step" => EngineKind::TimeStep { dt: 0.001 },
        "objects" => match own {
            Some(sectors) => EngineKind::Sectored {
                sectors,
                news: FixedNews::default(),
            },
            None => EngineKind::Objects {
                delay: NvDelay::Exact,
            },
        },
        "sectored" => EngineKind::Sectored {
            sectors: SectorChoice::Auto,
            news: FixedNews::default(),
        },
        "time-warp" => tw(own),
        "time-warp-sectored" => tw(Some(SectorChoice::Auto)),
        _ => panic!("no engine {name}"),
    }
}

#[test]
fn every_scenario_on_every_engine_ends_as_recorded() {
    let mut wrong = Vec::new();
    for &(name, engine_name, digest, events, messages) in TABLE {
        let s = scenario(name);
        let cfg = RunConfig {
            engine: engine(engine_name, &s),
            until: s.until,
            check: false,
            span: Default::default(),
            interrupt: None,
            checkpoint_every: None,
            thermostat: None,
        };
        let report = execute(&s, &cfg, &mut Ignore)
            .unwrap_or_else(|e| panic!("{name} on {engine_name}: {e}"));
        let summary = &report.summary;
        let e = &summary.events;
        let got_events = format!(
            "{} {} {} {}",
            e.ball_ball, e.ball_cushion, e.ball_corner, e.ball_pocket
        );
        let m = &summary.messages;
        let got_messages = MessageKind::ALL
            .iter()
            .map(|&k| m.get(k).to_string())
            .chain([m.total.to_string()])
            .collect::<Vec<_>>()
            .join(" ");
        let got = (
            summary.final_state_digest.as_str(),
            got_events,
            got_messages,
        );
        let want = (digest, events.to_string(), messages.to_string());
        if got != want {
            wrong.push(format!(
                "{name} on {engine_name}: got {got:?}, recorded {want:?}"
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}
