/*
 * PHOLD for ROOT-Sim core 3.x, written against its public API (ROOT-Sim.h) to be the same model as
 * poolsim's `poolsim phold` (crates/pdes-kernel/src/phold.rs), for bench/peers.sh.
 *
 * ROOT-Sim 3.0.0 ships a PHOLD only as a test (test/integration/phold.c) whose sizes are compile-time
 * constants and whose non-remote messages go back to the sender; this one takes its parameters on the
 * command line and draws receivers as poolsim does:
 *
 *   - N objects (LPs) split in P equal contiguous blocks, P = the partitions (the threads of the
 *     parallel run; ROOT-Sim maps LPs to threads in the same contiguous blocks, lid * T / N);
 *   - each LP starts with E messages to itself, at time lookahead + Exp(mean);
 *   - handling a message sends exactly one: with probability `remote` to another partition (uniform
 *     over the other P-1 partitions, then uniform over that block's LPs), else to a uniform LP of its
 *     own block; delay = lookahead + Exp(mean).
 *
 * Committed events are counted by the model: every LP counts the events it handles with a timestamp
 * before the end time in its (checkpointed, rolled back) state; the counts are summed at LP_FINI,
 * when every event before the end is committed, and printed as "committed events: N" after the run.
 * ROOT-Sim's own "Simulation completed in S seconds" line gives the time.
 *
 * Usage: rootsim_phold --lps N --threads T (0 = ROOT-Sim's serial runtime) --partitions P
 *                      --remote R --lookahead L --mean M --start-events E --end T
 *                      [--seed S] [--gvt-period-us U]
 */
#include <ROOT-Sim.h>

#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define EVENT 1

struct phold_state {
	uint64_t rng;      /* splitmix64 state, rolled back with the LP */
	uint64_t handled;  /* events handled with timestamp < end */
};

static uint64_t n_lps = 1024;
static unsigned n_parts = 1;
static double p_remote = 0.1;
static double lookahead = 0.0;
static double mean = 1.0;
static unsigned start_events = 16;
static double end_time = 100.0;
static uint64_t seed = 1;

static _Atomic uint64_t committed_total;

/* splitmix64's output function */
static uint64_t mix64(uint64_t z)
{
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

static uint64_t next_u64(struct phold_state *s)
{
	return mix64(s->rng += 0x9e3779b97f4a7c15ULL);
}

/* uniform in (0, 1] */
static double unif(struct phold_state *s)
{
	return (double)((next_u64(s) >> 11) + 1) * 0x1.0p-53;
}

/* uniform integer in [0, n) */
static uint64_t below(struct phold_state *s, uint64_t n)
{
	return (uint64_t)(unif(s) * (double)n) % n;
}

static unsigned partition_of(uint64_t lp)
{
	return (unsigned)(lp * n_parts / n_lps);
}

/* first LP of partition p (poolsim's block(): ceil(p * N / P)) */
static uint64_t block_start(unsigned p)
{
	return ((uint64_t)p * n_lps + n_parts - 1) / n_parts;
}

static lp_id_t draw_receiver(lp_id_t me, struct phold_state *s)
{
	unsigned own = partition_of(me);
	unsigned p = own;
	if(n_parts > 1 && unif(s) <= p_remote) {
		p = (unsigned)below(s, n_parts - 1);
		if(p >= own)
			p++;
	}
	uint64_t lo = block_start(p), hi = block_start(p + 1);
	if(hi <= lo)
		hi = lo + 1;
	return lo + below(s, hi - lo);
}

static double draw_delay(struct phold_state *s)
{
	return lookahead - mean * log(unif(s));
}

static void ProcessEvent(lp_id_t me, simtime_t now, unsigned event_type, const void *content, unsigned size,
    void *st)
{
	(void)content;
	(void)size;
	struct phold_state *s = st;
	char payload = 0;

	switch(event_type) {
		case LP_INIT:
			s = rs_malloc(sizeof(*s));
			if(s == NULL)
				abort();
			/* a hashed start point on splitmix64's sequence, so that no two LPs' streams are
			 * shifted copies of each other */
			s->rng = mix64(mix64(seed) ^ (me + 1));
			s->handled = 0;
			SetState(s);
			for(unsigned i = 0; i < start_events; i++)
				ScheduleNewEvent(me, draw_delay(s), EVENT, &payload, sizeof(payload));
			break;

		case LP_FINI:
			if(s != NULL)
				atomic_fetch_add_explicit(&committed_total, s->handled, memory_order_relaxed);
			break;

		case EVENT:
			if(now < end_time)
				s->handled++;
			lp_id_t to = draw_receiver(me, s);
			ScheduleNewEvent(to, now + draw_delay(s), EVENT, &payload, sizeof(payload));
			break;

		default:
			fprintf(stderr, "unknown event type %u\n", event_type);
			abort();
	}
}

static bool CanEnd(lp_id_t me, const void *snapshot)
{
	(void)me;
	(void)snapshot;
	return false;
}

static void usage(const char *argv0)
{
	fprintf(stderr,
	    "usage: %s --lps N --threads T (0 = serial) --partitions P --remote R --lookahead L --mean M\n"
	    "          --start-events E --end T [--seed S] [--gvt-period-us U]\n",
	    argv0);
	exit(2);
}

int main(int argc, char **argv)
{
	unsigned threads = 0, gvt_period_us = 1000;
	for(int i = 1; i < argc; i++) {
		const char *a = argv[i];
		if(i + 1 >= argc)
			usage(argv[0]);
		const char *v = argv[++i];
		if(!strcmp(a, "--lps"))
			n_lps = strtoull(v, NULL, 10);
		else if(!strcmp(a, "--threads"))
			threads = (unsigned)strtoul(v, NULL, 10);
		else if(!strcmp(a, "--partitions"))
			n_parts = (unsigned)strtoul(v, NULL, 10);
		else if(!strcmp(a, "--remote"))
			p_remote = strtod(v, NULL);
		else if(!strcmp(a, "--lookahead"))
			lookahead = strtod(v, NULL);
		else if(!strcmp(a, "--mean"))
			mean = strtod(v, NULL);
		else if(!strcmp(a, "--start-events"))
			start_events = (unsigned)strtoul(v, NULL, 10);
		else if(!strcmp(a, "--end"))
			end_time = strtod(v, NULL);
		else if(!strcmp(a, "--seed"))
			seed = strtoull(v, NULL, 10);
		else if(!strcmp(a, "--gvt-period-us"))
			gvt_period_us = (unsigned)strtoul(v, NULL, 10);
		else
			usage(argv[0]);
	}
	if(n_lps == 0 || n_parts == 0 || n_parts > n_lps)
		usage(argv[0]);

	struct simulation_configuration conf = {
	    .lps = n_lps,
	    .n_threads = threads ? threads : 1,
	    .termination_time = end_time,
	    .gvt_period = gvt_period_us,
	    .log_level = LOG_INFO,
	    .stats_file = NULL,
	    .ckpt_interval = 0, /* automatic checkpoint interval */
	    .core_binding = true,
	    .serial = threads == 0,
	    .dispatcher = ProcessEvent,
	    .committed = CanEnd,
	};
	if(RootsimInit(&conf))
		return 1;
	int ret = RootsimRun();
	printf("committed events: %llu\n", (unsigned long long)atomic_load(&committed_total));
	return ret;
}
