/*
** conifit predict: a saved fit's prediction of tables (cli_predict.c). Private to src/cli/.
*/
#ifndef CF_CLI_PREDICT_H
#define CF_CLI_PREDICT_H

/* The subcommand: parses its arguments (argv[0] "predict") and returns an exit status. */
int cf_cli_predict(int argc, char **argv);

#endif
